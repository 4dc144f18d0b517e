// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/ballbar, src/circular and src/probe (kept in src/io, below all three): number
// formatting of NC words, each dialect's comment writer, and the program preamble per dialect,
// shared by the NC writer of the rotary-axis test (nc_program.cpp), of the circular tests
// (src/circular/plan.cpp) and of the touch probe (src/probe/nc_program.cpp).

#include <cstdio>
#include <functional>
#include <string>

#include "rotacal/core/error.hpp"
#include "rotacal/io/controller_comment.hpp"
#include "rotacal/io/nc_dialect.hpp"

namespace rotacal::nc_detail {

/// Fixed-point text with `decimals` digits; "-0.0000" is written as "0.0000".
inline std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  bool all_zero = true;
  for (char c : s)
    if (c != '-' && c != '0' && c != '.') all_zero = false;
  if (all_zero && !s.empty() && s[0] == '-') s.erase(0, 1);
  return s;
}

/// Up to 9 significant digits, for comments.
inline std::string general(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

/// The comment writer of an NC dialect (io/controller_comment.hpp): every comment of a program,
/// fixed or free text, goes through it.
inline CommentDialect comment_dialect(NcDialect d) {
  switch (d) {
    case NcDialect::linuxcnc:
      return CommentDialect::linuxcnc;
    case NcDialect::heidenhain:
      return CommentDialect::heidenhain;
    case NcDialect::siemens:
      return CommentDialect::siemens;
    case NcDialect::fanuc:
      return CommentDialect::fanuc;
  }
  ROTACAL_ASSERT(false);
  return CommentDialect::linuxcnc;
}

/// What differs between the programs that share write_preamble.
struct Preamble {
  std::string writer;       ///< function named in error messages, e.g. "write_nc_program"
  std::string program;      ///< "TCP program" / "program": what needs a tool, in the message
  std::string fanuc_title;  ///< comment of the fanuc O line, e.g. "ROTACAL BALLBAR"
  /// linuxcnc: G43 H<tool> only on a table machine (a head machine's machine-axis program
  /// already holds the tool vector, formats.md).
  bool head_machine = false;
};

/// Checks the options the preamble uses (decimals 0..9, tool >= 0 and > 0 for heidenhain and
/// fanuc, heidenhain program_name one word of letters, digits, '_' and '-', fanuc
/// program_number 1..9999; InvalidArgument naming `p.writer` and the option) and writes,
/// through `line`, each dialect's opening blocks with the header comments (`header`) where
/// the dialect puts them:
///   linuxcnc:   header, G21 G90 G94 G17 G40 G49 G80, G43 H<tool> (tool > 0, table machine)
///   heidenhain: BEGIN PGM <name> MM, header, FUNCTION RESET TCPM, TOOL CALL <tool> Z
///   siemens:    header, TRAFOOF, G71 G90 G94 G17 G40 G64, T<tool> D1 (tool > 0)
///   fanuc:      %, O<number> (<title>), header, G21 G90 G94 G17 G40 G49 G80
inline void write_preamble(NcDialect d, const NcProgramOptions& o, const Preamble& p,
                           const std::function<void(const std::string&)>& line,
                           const std::function<void()>& header) {
  if (o.decimals < 0 || o.decimals > 9)
    throw InvalidArgument(p.writer + ": decimals must be in 0..9, got " +
                          std::to_string(o.decimals));
  if (o.tool < 0) throw InvalidArgument(p.writer + ": tool must be >= 0");
  if ((d == NcDialect::heidenhain || d == NcDialect::fanuc) && o.tool == 0)
    throw InvalidArgument(p.writer + ": the " + to_string(d) + " " + p.program +
                          " needs a tool number (tool = 0 given)");
  switch (d) {
    case NcDialect::linuxcnc:
      header();
      line("G21 G90 G94 G17 G40 G49 G80");
      if (o.tool > 0 && !p.head_machine) line("G43 H" + std::to_string(o.tool));
      break;
    case NcDialect::heidenhain:
      // It is written outside any comment (BEGIN PGM / END PGM): only a plain name.
      if (o.program_name.empty() || o.program_name.size() > 64 ||
          o.program_name.find_first_not_of(
              "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") !=
              std::string::npos)
        throw InvalidArgument(
            p.writer + ": program_name must be one word of letters, digits, '_' and '-', got '" +
            o.program_name + "'");
      line("BEGIN PGM " + o.program_name + " MM");
      header();
      line("FUNCTION RESET TCPM");
      line("TOOL CALL " + std::to_string(o.tool) + " Z");
      break;
    case NcDialect::siemens:
      header();
      line("TRAFOOF");
      line("G71 G90 G94 G17 G40 G64");
      if (o.tool > 0) line("T" + std::to_string(o.tool) + " D1");
      break;
    case NcDialect::fanuc: {
      if (o.program_number < 1 || o.program_number > 9999)
        throw InvalidArgument(p.writer + ": program_number must be in 1..9999");
      line("%");
      char number[16];
      std::snprintf(number, sizeof number, "O%04d", o.program_number);
      line(std::string(number) + " " + comment_lines(CommentDialect::fanuc, p.fanuc_title).front());
      header();
      line("G21 G90 G94 G17 G40 G49 G80");
      break;
    }
  }
}

}  // namespace rotacal::nc_detail
