// SPDX-License-Identifier: BSD-3-Clause
// The NC program preamble shared by the rotary-axis and the circular-test writers
// (src/io/nc_words.hpp): what it writes per dialect, that it is what both programs open
// with, and the errors it raises in each writer's name.
#include <algorithm>
#include <catch2/catch.hpp>
#include <sstream>

#include "../../src/io/nc_words.hpp"
#include "rotacal/ballbar/nc_program.hpp"
#include "rotacal/ballbar/plan.hpp"
#include "rotacal/circular/plan.hpp"

using namespace rotacal;

namespace {

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

bool is_comment(const std::string& l) {
  return (!l.empty() && l[0] == '(') || l.rfind("; ", 0) == 0;
}

// The preamble's blocks with the header left empty (a "HEADER" marker where it goes).
std::vector<std::string> preamble(NcDialect d, const NcProgramOptions& o,
                                  const nc_detail::Preamble& p) {
  std::vector<std::string> out;
  nc_detail::write_preamble(
      d, o, p, [&](const std::string& s) { out.push_back(s); }, [&] { out.push_back("HEADER"); });
  return out;
}

// The first blocks of a program that are not comments, without heidenhain's line numbers.
std::vector<std::string> opening_blocks(const std::string& program, NcDialect d, std::size_t n) {
  std::vector<std::string> out;
  for (std::string l : lines_of(program)) {
    if (d == NcDialect::heidenhain) l = l.substr(l.find(' ') + 1);
    if (is_comment(l)) continue;
    out.push_back(l);
    if (out.size() == n) break;
  }
  return out;
}

std::vector<std::string> without_header(std::vector<std::string> v) {
  v.erase(std::remove(v.begin(), v.end(), "HEADER"), v.end());
  return v;
}

}  // namespace

TEST_CASE("preamble: each dialect's opening blocks, header where the dialect puts it") {
  NcProgramOptions o;
  o.tool = 3;
  const nc_detail::Preamble p{"writer", "program", "TITLE", false};
  CHECK(preamble(NcDialect::linuxcnc, o, p) ==
        std::vector<std::string>{"HEADER", "G21 G90 G94 G17 G40 G49 G80", "G43 H3"});
  CHECK(preamble(NcDialect::heidenhain, o, p) ==
        std::vector<std::string>{"BEGIN PGM ROTACAL_BALLBAR MM", "HEADER", "FUNCTION RESET TCPM",
                                 "TOOL CALL 3 Z"});
  CHECK(preamble(NcDialect::siemens, o, p) ==
        std::vector<std::string>{"HEADER", "TRAFOOF", "G71 G90 G94 G17 G40 G64", "T3 D1"});
  CHECK(preamble(NcDialect::fanuc, o, p) ==
        std::vector<std::string>{"%", "O1000 (TITLE)", "HEADER", "G21 G90 G94 G17 G40 G49 G80"});
  // No G43 on a head machine (linuxcnc) and no tool call without a tool.
  nc_detail::Preamble head = p;
  head.head_machine = true;
  CHECK(preamble(NcDialect::linuxcnc, o, head).size() == 2);
  o.tool = 0;
  CHECK(preamble(NcDialect::siemens, o, p).size() == 3);
  CHECK(preamble(NcDialect::linuxcnc, o, p).size() == 2);
}

TEST_CASE("preamble: both NC writers open with it") {
  const BallbarPlan rotary = plan_ballbar_test(BallbarSetup{});
  CircularTestPlan cp;
  cp.planes = {CircularPlane::XY};
  cp.feeds_mm_per_min = {1000.0};
  const CircularPlanResult circular = plan_circular_test(cp);
  const NcProgramOptions o;
  for (NcDialect d :
       {NcDialect::linuxcnc, NcDialect::heidenhain, NcDialect::siemens, NcDialect::fanuc}) {
    INFO(to_string(d));
    const auto rot = without_header(
        preamble(d, o, {"write_nc_program", "TCP program", "ROTACAL BALLBAR", false}));
    CHECK(opening_blocks(write_nc_program(rotary, d), d, rot.size()) == rot);
    auto circ = without_header(
        preamble(d, o, {"write_circular_nc_program", "program", "ROTACAL CIRCULAR", false}));
    if (d == NcDialect::fanuc) circ.push_back("G43 H1");  // the circular program's own block
    CHECK(opening_blocks(write_circular_nc_program(circular, d), d, circ.size()) == circ);
  }
}

TEST_CASE("preamble: bad options are refused in the writer's name") {
  CircularTestPlan cp;
  cp.planes = {CircularPlane::XY};
  cp.feeds_mm_per_min = {1000.0};
  const CircularPlanResult circular = plan_circular_test(cp);
  NcProgramOptions o;
  o.decimals = 10;
  CHECK_THROWS_WITH(write_circular_nc_program(circular, NcDialect::linuxcnc, o),
                    "write_circular_nc_program: decimals must be in 0..9, got 10");
  o = {};
  o.tool = 0;
  CHECK_THROWS_WITH(write_circular_nc_program(circular, NcDialect::heidenhain, o),
                    "write_circular_nc_program: the heidenhain program needs a tool number (tool "
                    "= 0 given)");
  CHECK_THROWS_WITH(preamble(NcDialect::fanuc, o, {"write_nc_program", "TCP program", "T", false}),
                    "write_nc_program: the fanuc TCP program needs a tool number (tool = 0 given)");
  o = {};
  o.program_name = "TWO WORDS";
  CHECK_THROWS_WITH(
      write_circular_nc_program(circular, NcDialect::heidenhain, o),
      "write_circular_nc_program: program_name must be one word of letters, digits, '_' and '-', "
      "got 'TWO WORDS'");
  // It is written outside any comment (BEGIN PGM, END PGM): a line end or ';' is refused.
  for (const char* name : {"P\nL Z-500 FMAX", "P\rM30", "P;X", "P~", "P(1)"}) {
    o.program_name = name;
    CHECK_THROWS_AS(write_circular_nc_program(circular, NcDialect::heidenhain, o), InvalidArgument);
  }
  o = {};
  o.program_number = 0;
  CHECK_THROWS_AS(write_circular_nc_program(circular, NcDialect::fanuc, o), InvalidArgument);
  o.tool = -1;
  CHECK_THROWS_WITH(write_circular_nc_program(circular, NcDialect::siemens, o),
                    "write_circular_nc_program: tool must be >= 0");
}
