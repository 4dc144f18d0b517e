// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Free text as comment lines of a file that a controller executes: the only way any text
/// that is not the writer's own code (a machine's name, a session path, a model's source, a
/// label, a date) reaches an NC program or a controller file. A comment cannot end early:
///
/// - every byte outside printable ASCII is replaced: a control character (newline, CR, NUL,
///   ...) by its caret form (^J, ^M, ^@), any other byte by '?'; a controller's reader ends a
///   block at a line end, and some choke on bytes they do not know;
/// - '\' becomes '/' (ISG joins a block ending in '\' with the next line);
/// - what ends the dialect's comment or block, or starts an active one, is replaced (below);
/// - a text longer than one line is cut into several whole comment lines: a reader that stops
///   at a length (LinuxCNC at 252 characters, halcmd's fgets at 1023) would otherwise refuse
///   the file or read the rest of the line as a command.
///
/// The replacements keep the text readable; nothing is refused.

#include <string>
#include <string_view>
#include <vector>

namespace rotacal {

enum class CommentDialect {
  /// LinuxCNC RS274/NGC: "(text)". '(' and ')' become '[' and ']' (comments do not nest);
  /// a line that LinuxCNC would read as an active comment (MSG, DEBUG, PRINT, LOG..., PY...,
  /// ABORT, PROBEOPEN, PROBECLOSE, AXIS, or any word followed by a comma) starts with "- ".
  linuxcnc,
  /// FANUC ISO: "(TEXT)" in capitals; '(' ')' as for linuxcnc, ';' (end of block) becomes ','
  /// and '%' (end of tape) '_'.
  fanuc,
  /// HEIDENHAIN conversational: "; text"; '~' (a block continued on the next line) becomes '-'.
  heidenhain,
  /// SINUMERIK: "; text".
  siemens,
  /// ISG/Beckhoff NC program: "; text".
  isg,
  /// HAL files (halcmd), ISG channel parameter lists and the HEIDENHAIN/FANUC mapping sheets:
  /// "# text"; nothing after '#' is read, so only line ends and length matter.
  hash,
};

/// "linuxcnc", "fanuc", "heidenhain", "siemens", "isg", "hash".
std::string to_string(CommentDialect dialect);
/// Inverse of to_string; InvalidArgument naming the unknown text and the known ones.
CommentDialect parse_comment_dialect(const std::string& text);

/// Longest comment line written, delimiters included: 240 for the NC dialects (LinuxCNC refuses
/// lines over 252; HEIDENHAIN's block number comes in front), 1000 for hash (halcmd reads 1023).
std::size_t comment_line_width(CommentDialect dialect);

/// `text` as one or more whole comment lines of `dialect` (without line ends): one line when
/// it fits comment_line_width, the empty text as the bare delimiters ("()", ";", "#").
std::vector<std::string> comment_lines(CommentDialect dialect, std::string_view text);

}  // namespace rotacal
