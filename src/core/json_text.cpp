// SPDX-License-Identifier: BSD-3-Clause
// Strict, bounded JSON text (core/json_text.hpp).
#include "rotacal/core/json_text.hpp"

#include <utility>

#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

std::pair<int, int> line_column(const std::string& text, std::size_t byte) {
  int line = 1, col = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return {line, col};
}

[[noreturn]] void refuse(const std::string& text, const std::string& source, std::size_t byte,
                         const std::string& what) {
  const auto lc = line_column(text, byte);
  throw ParseError(source, lc.first, lc.second, what);
}

}  // namespace

void check_json_bounds(const std::string& text, const std::string& source) {
  const std::size_t max_containers = kJsonContainerAllowance + text.size() / kJsonBytesPerContainer;
  std::size_t containers = 0;
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;  // the escaped character cannot end the string
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      if (++depth > kMaxJsonDepth)
        refuse(text, source, i,
               "nested deeper than " + std::to_string(kMaxJsonDepth) +
                   " levels of objects and arrays: not a rotacal file");
      if (++containers > max_containers)
        refuse(text, source, i,
               "more than " + std::to_string(max_containers) + " objects and arrays in " +
                   std::to_string(text.size()) + " bytes (at most one per " +
                   std::to_string(kJsonBytesPerContainer) + " bytes): not a rotacal file");
    } else if (c == '}' || c == ']') {
      --depth;  // unbalanced brackets are the parser's syntax error
    }
  }
}

nlohmann::ordered_json parse_json(const std::string& text, const std::string& source) {
  check_json_bounds(text, source);
  try {
    // Strict RFC 8259: NaN/Infinity tokens, comments and trailing commas are syntax errors.
    return nlohmann::ordered_json::parse(text);
  } catch (const nlohmann::ordered_json::parse_error& e) {
    std::string what = e.what();
    const std::size_t colon = what.find("syntax error");
    if (colon != std::string::npos) what = what.substr(colon);
    refuse(text, source, e.byte > 0 ? e.byte - 1 : 0, "not valid JSON: " + printable(what));
  } catch (const nlohmann::ordered_json::exception& e) {
    // e.g. out_of_range 406, a number beyond double ("1e99999"): found by fuzz_file_readers.
    throw ParseError(source, 0, 0, std::string("not valid JSON: ") + printable(e.what()));
  }
}

std::string printable(const std::string& what) {
  static const char hex[] = "0123456789ABCDEF";
  std::string out;
  for (const char ch : what) {
    const auto u = static_cast<unsigned char>(ch);
    if (u >= 0x20 && u < 0x7F) {
      out += ch;
    } else {
      out += "\\x";
      out += hex[u >> 4];
      out += hex[u & 15];
    }
  }
  return out.size() > 160 ? out.substr(0, 157) + "..." : out;
}

}  // namespace rotacal
