// SPDX-License-Identifier: BSD-3-Clause
// core/json_text.hpp: strict JSON, bounded in nesting and in objects and arrays per byte.
#include <algorithm>
#include <catch2/catch.hpp>
#include <string>

#include "rotacal/core/error.hpp"
#include "rotacal/core/json_text.hpp"
#include "rotacal/io/model_file.hpp"

using namespace rotacal;

namespace {
std::string nested(int depth, const std::string& inner = "0") {
  return std::string(static_cast<std::size_t>(depth), '[') + inner +
         std::string(static_cast<std::size_t>(depth), ']');
}
}  // namespace

TEST_CASE("nesting up to the limit is read, one level more is refused at its line and column") {
  CHECK(parse_json(nested(kMaxJsonDepth), "ok.json").is_array());
  try {
    parse_json("{\n \"a\": " + nested(kMaxJsonDepth), "deep.json");
    FAIL("accepted");
  } catch (const ParseError& e) {
    CHECK(e.file() == "deep.json");
    CHECK(e.line() == 2);
    CHECK(e.column() == 7 + kMaxJsonDepth - 1);
    CHECK_THAT(e.what(), Catch::Contains("nested deeper than 64"));
  }
}

TEST_CASE("50,000 nested brackets are refused before the parser, without recursion") {
  // Issue 32: in an ignored member of a model file they overflowed the stack of the bindings.
  const std::string doc = "{\"format\": \"rotacal-model/1\", \"x\": " + nested(50000) + "}";
  CHECK_THROWS_WITH(parse_json(doc, "m.json"),
                    Catch::Contains("m.json:1:") && Catch::Contains("nested deeper"));
  CHECK_THROWS_AS(parse_model(doc, "m.json"), ParseError);
}

TEST_CASE("a flood of empty objects is refused by objects per byte, a model's own layout is not") {
  std::string flood = "[";
  for (int i = 0; i < 100000; ++i) flood += i ? ",{}" : "{}";
  flood += "]";
  CHECK_THROWS_WITH(parse_json(flood, "f.json"), Catch::Contains("objects and arrays"));
  // A covariance matrix: a row of numbers per array, well within one container per 16 bytes.
  std::string matrix = "[";
  for (int r = 0; r < 300; ++r) {
    matrix += r ? ",[" : "[";
    for (int c = 0; c < 300; ++c) matrix += (c ? "," : "") + std::string("1.2345678901234e-07");
    matrix += "]";
  }
  matrix += "]";
  CHECK(parse_json(matrix, "cov.json").size() == 300);
  // Small files may be all brackets (the allowance): [[],[]] and {} stay valid JSON.
  CHECK(parse_json("[[],[],{}]", "small.json").size() == 3);
}

TEST_CASE("brackets inside strings are text, not nesting") {
  const std::string s =
      "{\"name\": \"" + std::string(1000, '[') + "\\\"" + std::string(1000, '{') + "\"}";
  CHECK(parse_json(s, "s.json")["name"].get<std::string>().size() == 2001);
}

TEST_CASE("syntax errors and NaN are ParseErrors with the line and column") {
  try {
    parse_json("{\n \"a\": NaN}", "n.json");
    FAIL("accepted");
  } catch (const ParseError& e) {
    CHECK(e.line() == 2);
    CHECK_THAT(e.what(), Catch::Contains("not valid JSON"));
  }
  CHECK_THROWS_AS(parse_json("{\"a\": 1e99999}", "big.json"), ParseError);
}

TEST_CASE("a byte that is not UTF-8 is named in printable text") {
  // nlohmann quotes the bytes it stopped at; raw, they made the message itself undecodable.
  try {
    parse_json("{\"kind\": \"\xff\"}", "u.json");
    FAIL("accepted");
  } catch (const ParseError& e) {
    const std::string what = e.what();
    CHECK_THAT(what, Catch::Contains("u.json:1:") && Catch::Contains("\\xFF"));
    CHECK(std::all_of(what.begin(), what.end(),
                      [](char c) { return static_cast<unsigned char>(c) < 0x80; }));
  }
}
