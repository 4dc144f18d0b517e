// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The one strict JSON reader behind every JSON file rotacal reads (model files, machine
/// descriptions, and from Python the budget sizes, exports, diagnoses and tables), bounded so
/// that no input can exhaust the stack or the memory, as the session readers bound theirs:
///
/// - nesting: at most kMaxJsonDepth levels of objects and arrays (a reader or a conversion to
///   Python that recurses per level then stays within any stack);
/// - memory: at most one object or array per kJsonBytesPerContainer bytes of input, plus
///   kJsonContainerAllowance. A parsed object or array costs about 50 bytes in the C++
///   document and as much again as a Python dict or list, while `{}` takes 3 bytes of input: a
///   file of nothing but empty objects would need ~40x its size. rotacal's own files hold one
///   per 60 to 200 bytes. A number or string costs at most ~12x its input text.
///
/// The bounds are checked by a scan of the text before it is parsed, so a refusal costs no
/// memory and names the line and column.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace rotacal {

inline constexpr int kMaxJsonDepth = 64;
inline constexpr std::size_t kJsonBytesPerContainer = 16;
inline constexpr std::size_t kJsonContainerAllowance = 4096;

/// Refuse a JSON text beyond the bounds above: ParseError naming `source`, line and column.
/// Does not check the syntax (parse_json does).
void check_json_bounds(const std::string& text, const std::string& source);

/// Strict RFC 8259 JSON (no NaN or Infinity tokens, comments or trailing commas) within the
/// bounds above. Throws ParseError naming `source`, line and column.
nlohmann::ordered_json parse_json(const std::string& text, const std::string& source);

/// Text fit for a message: bytes outside printable ASCII (terminal escapes, control bytes,
/// bytes that are not UTF-8) shown as \xNN, at most 160 characters in all. nlohmann's
/// messages quote the bytes they stopped at; a reader echoes a bad line with it.
std::string printable(const std::string& text);

}  // namespace rotacal
