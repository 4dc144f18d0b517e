// SPDX-License-Identifier: BSD-3-Clause
// Free text as comment lines that no controller reads as a command.
#include "rotacal/io/controller_comment.hpp"

#include <array>
#include <cctype>

#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

constexpr std::array<CommentDialect, 6> kDialects = {
    CommentDialect::linuxcnc, CommentDialect::fanuc, CommentDialect::heidenhain,
    CommentDialect::siemens,  CommentDialect::isg,   CommentDialect::hash};

bool parenthesised(CommentDialect d) {
  return d == CommentDialect::linuxcnc || d == CommentDialect::fanuc;
}

// One printable ASCII character as the dialect may carry it inside a comment.
char inert(CommentDialect d, char c) {
  if (c == '\\') return '/';
  if (parenthesised(d) && c == '(') return '[';
  if (parenthesised(d) && c == ')') return ']';
  if (d == CommentDialect::fanuc) {
    if (c == ';') return ',';
    if (c == '%') return '_';
    return static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  if (d == CommentDialect::heidenhain && c == '~') return '-';
  return c;
}

std::string escaped(CommentDialect d, std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x80) {
      out += '?';
    } else if (c < 0x20 || c == 0x7F) {  // caret form: ^J for a newline, ^? for DEL
      out += '^';
      out += inert(d, static_cast<char>(c ^ 0x40));
    } else {
      out += inert(d, ch);
    }
  }
  return out;
}

// LinuxCNC's interpreter acts on a comment whose text (leading blanks skipped, any case)
// starts with one of these (interp_convert.cc, convert_comment; the AXIS preview reads
// "AXIS,"), and every such command is a word and a comma: either makes the line active.
bool active_in_linuxcnc(const std::string& chunk) {
  std::size_t i = chunk.find_first_not_of(' ');
  if (i == std::string::npos) return false;
  std::string lower;
  for (std::size_t k = i; k < chunk.size(); ++k)
    lower += static_cast<char>(std::tolower(static_cast<unsigned char>(chunk[k])));
  static const char* const kActive[] = {"msg",   "debug",     "print",      "log",  "py",
                                        "abort", "probeopen", "probeclose", "axis", "system"};
  for (const char* word : kActive)
    if (lower.rfind(word, 0) == 0) return true;
  std::size_t w = 0;
  while (w < lower.size() && std::isalpha(static_cast<unsigned char>(lower[w]))) ++w;
  return w > 0 && w < lower.size() && lower[w] == ',';
}

std::string delimited(CommentDialect d, const std::string& chunk) {
  if (parenthesised(d)) return "(" + chunk + ")";
  const char* mark = d == CommentDialect::hash ? "#" : ";";
  return chunk.empty() ? std::string(mark) : std::string(mark) + " " + chunk;
}

}  // namespace

std::string to_string(CommentDialect dialect) {
  switch (dialect) {
    case CommentDialect::linuxcnc:
      return "linuxcnc";
    case CommentDialect::fanuc:
      return "fanuc";
    case CommentDialect::heidenhain:
      return "heidenhain";
    case CommentDialect::siemens:
      return "siemens";
    case CommentDialect::isg:
      return "isg";
    case CommentDialect::hash:
      return "hash";
  }
  ROTACAL_ASSERT(false);
  return {};
}

CommentDialect parse_comment_dialect(const std::string& text) {
  std::string known;
  for (CommentDialect d : kDialects) {
    if (to_string(d) == text) return d;
    known += (known.empty() ? "" : ", ") + to_string(d);
  }
  throw InvalidArgument("unknown comment dialect '" + text + "' (known: " + known + ")");
}

std::size_t comment_line_width(CommentDialect dialect) {
  return dialect == CommentDialect::hash ? 1000 : 240;
}

std::vector<std::string> comment_lines(CommentDialect d, std::string_view text) {
  const std::string safe = escaped(d, text);
  // Room for the delimiters (2) and, in linuxcnc, the "- " that disarms an active comment.
  const std::size_t room = comment_line_width(d) - (d == CommentDialect::linuxcnc ? 4 : 2);
  std::vector<std::string> lines;
  std::size_t at = 0;
  do {
    std::size_t n = std::min(room, safe.size() - at);
    if (at + n < safe.size()) {  // break at the last blank of the second half, if any
      const std::size_t blank = safe.rfind(' ', at + n);
      if (blank != std::string::npos && blank > at + n / 2) n = blank - at;
    }
    std::string chunk = safe.substr(at, n);
    at += n;
    while (at < safe.size() && safe[at] == ' ') ++at;  // the blank the line broke at
    if (d == CommentDialect::linuxcnc && active_in_linuxcnc(chunk)) chunk = "- " + chunk;
    lines.push_back(delimited(d, chunk));
  } while (at < safe.size());
  return lines;
}

}  // namespace rotacal
