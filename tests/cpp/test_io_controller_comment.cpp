// SPDX-License-Identifier: BSD-3-Clause
// Tests of rotacal/io/controller_comment.hpp: whatever the text, each dialect's comment lines
// are whole comments that its controller cannot read as a block or a command.
#include <catch2/catch.hpp>
#include <cctype>
#include <string>
#include <vector>

#include "rotacal/core/error.hpp"
#include "rotacal/io/controller_comment.hpp"

using namespace rotacal;

namespace {

const CommentDialect kAll[] = {CommentDialect::linuxcnc,   CommentDialect::fanuc,
                               CommentDialect::heidenhain, CommentDialect::siemens,
                               CommentDialect::isg,        CommentDialect::hash};

// Every dialect's dangerous characters, each where it would do harm: a line end before a
// block, comment terminators, block ends, tape ends, active comments, continuations, bytes
// outside ASCII, and a text longer than any reader's line.
std::vector<std::string> hostile_texts() {
  std::vector<std::string> t = {
      "x\nG0 Z-500\n",
      "x\r\nG0 Z-500\r",
      "x\rM30",
      "\n G0 Z-500",
      "session.csv\nloadusr -w touch X\n",
      "a) G0 Z-500 (b",
      "(nested (comment))",
      "a; G0 Z-500",
      "%\nG0 Z-500\n%",
      "* - structure\n* G0",
      "$TC_CARR4[1]=500\n$TC_CARR5[1]=500",
      "#<_x> = 500\n#1=2",
      "MSG, injected",
      "  debug,#5400",
      "LogOpen,/tmp/x",
      "PY, import os",
      "probeopen /tmp/probe.txt",
      "AXIS,hide",
      "word,comma",
      "ends in a backslash \\",
      "ends in a tilde ~",
      std::string("nul \0 byte\x1b[31m\x7f", 16),  // 16 characters, the NUL among them
      "utf-8 \xc3\xa9 and a line separator \xe2\x80\xa8 G0 Z-500",
      std::string(300, 'a') + "\nG0 Z-500",
      std::string(1500, 'b') + "loadusr -w touch X",
      std::string(239, 'c') + ") G0 Z-500",
      "",
  };
  std::string words;
  for (int i = 0; i < 400; ++i)
    words += "msg, word ";  // every cut line starts like an active comment
  t.push_back(words);
  return t;
}

bool active_in_linuxcnc(std::string body) {
  const std::size_t i = body.find_first_not_of(' ');
  if (i == std::string::npos) return false;
  for (char& c : body) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  body = body.substr(i);
  for (const char* w :
       {"msg", "debug", "print", "log", "py", "abort", "probeopen", "probeclose", "axis"})
    if (body.rfind(w, 0) == 0) return true;
  const std::size_t comma = body.find(',');
  return comma != std::string::npos && comma > 0 &&
         body.find_first_not_of("abcdefghijklmnopqrstuvwxyz") == comma;
}

// The properties every comment line of `d` must have; returns what is wrong, empty if none.
std::string fault(CommentDialect d, const std::string& l) {
  if (l.size() > comment_line_width(d))
    return "longer than " + std::to_string(comment_line_width(d));
  for (char c : l)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e)
      return "a byte outside printable ASCII";
  if (l.find('\\') != std::string::npos) return "a backslash";
  switch (d) {
    case CommentDialect::linuxcnc:
    case CommentDialect::fanuc: {
      if (l.size() < 2 || l.front() != '(' || l.back() != ')') return "not one (...) comment";
      const std::string body = l.substr(1, l.size() - 2);
      if (body.find_first_of("()") != std::string::npos) return "a parenthesis inside";
      if (d == CommentDialect::linuxcnc && active_in_linuxcnc(body)) return "an active comment";
      if (d == CommentDialect::fanuc && body.find_first_of(";%") != std::string::npos)
        return "';' or '%'";
      if (d == CommentDialect::fanuc)
        for (char c : body)
          if (std::islower(static_cast<unsigned char>(c))) return "lower case";
      break;
    }
    case CommentDialect::heidenhain:
      if (l.find('~') != std::string::npos) return "a '~'";
      [[fallthrough]];
    case CommentDialect::siemens:
    case CommentDialect::isg:
      if (l.front() != ';') return "not a ; comment";
      break;
    case CommentDialect::hash:
      if (l.front() != '#') return "not a # comment";
      break;
  }
  return {};
}

}  // namespace

TEST_CASE("every dialect: hostile text gives only whole, inert comment lines") {
  for (CommentDialect d : kAll)
    for (const std::string& text : hostile_texts()) {
      const std::vector<std::string> lines = comment_lines(d, text);
      REQUIRE_FALSE(lines.empty());
      for (const std::string& l : lines) {
        INFO(to_string(d) << ": " << l);
        CHECK(fault(d, l).empty());
      }
    }
}

TEST_CASE("the checks above catch a comment written verbatim") {
  // What the writers did before: the text between the delimiters as it came.
  CHECK_FALSE(fault(CommentDialect::linuxcnc, "(x\nG0 Z-500\n)").empty());
  CHECK_FALSE(fault(CommentDialect::linuxcnc, "(MSG, injected)").empty());
  CHECK_FALSE(fault(CommentDialect::fanuc, "(A; G0 Z-500)").empty());
  CHECK_FALSE(fault(CommentDialect::heidenhain, "; ends in a tilde ~").empty());
  CHECK_FALSE(fault(CommentDialect::hash, "# " + std::string(1500, 'b')).empty());
}

TEST_CASE("the text stays readable: what each dialect replaces, and nothing else") {
  using V = std::vector<std::string>;
  CHECK(comment_lines(CommentDialect::linuxcnc, "machine: x\nG0 Z-500\n") ==
        V{"(machine: x^JG0 Z-500^J)"});
  CHECK(comment_lines(CommentDialect::linuxcnc, "a (b) c") == V{"(a [b] c)"});
  CHECK(comment_lines(CommentDialect::linuxcnc, " MSG, hi") == V{"(-  MSG, hi)"});
  CHECK(comment_lines(CommentDialect::linuxcnc, "pivot: 1, 2") == V{"(pivot: 1, 2)"});
  CHECK(comment_lines(CommentDialect::fanuc, "a(b); 5%") == V{"(A[B], 5_)"});
  CHECK(comment_lines(CommentDialect::heidenhain, "c:\\x ~") == V{"; c:/x -"});
  CHECK(comment_lines(CommentDialect::siemens, "$TC_CARR1[1]=0\r\nM30") ==
        V{"; $TC_CARR1[1]=0^M^JM30"});
  CHECK(comment_lines(CommentDialect::isg, "caf\xc3\xa9") == V{"; caf??"});
  CHECK(comment_lines(CommentDialect::hash, "s.csv\nloadusr -w touch X") ==
        V{"# s.csv^Jloadusr -w touch X"});
  CHECK(comment_lines(CommentDialect::hash, "") == V{"#"});
  CHECK(comment_lines(CommentDialect::siemens, "") == V{";"});
  CHECK(comment_lines(CommentDialect::linuxcnc, "") == V{"()"});
}

TEST_CASE("a long text is cut into whole lines at blanks, and nothing is lost") {
  std::string text;
  for (int i = 0; i < 100; ++i) text += (i ? " word" : "word") + std::to_string(i);
  for (CommentDialect d : {CommentDialect::linuxcnc, CommentDialect::siemens}) {
    const std::vector<std::string> lines = comment_lines(d, text);
    REQUIRE(lines.size() > 1);
    std::string joined;
    for (const std::string& l : lines) {
      CHECK(l.size() <= comment_line_width(d));
      const std::string body =
          d == CommentDialect::linuxcnc ? l.substr(1, l.size() - 2) : l.substr(2);
      joined += (joined.empty() ? "" : " ") + body;
      CHECK(body.back() != ' ');
    }
    CHECK(joined == text);
  }
}

TEST_CASE("dialect names") {
  for (CommentDialect d : kAll) CHECK(parse_comment_dialect(to_string(d)) == d);
  CHECK_THROWS_AS(parse_comment_dialect("hal"), InvalidArgument);
  CHECK_THROWS_WITH(parse_comment_dialect("x"), Catch::Contains("unknown comment dialect 'x'"));
}
