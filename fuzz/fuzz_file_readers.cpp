// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: the session readers (rotacal-ballbar/1, rotacal-rtest/1, rotacal-probe/1) and
// the model-file reader must refuse any bytes with a rotacal::Error, never crash, read out of
// bounds or throw anything else; what they accept, their writers write back and they read again
// identically.
#include <cstdlib>
#include <sstream>
#include <string>

#include "rotacal/core/error.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/io/model_file.hpp"
#include "rotacal/io/probe_file.hpp"

using namespace rotacal;

namespace {

template <typename Parse, typename Format>
void session_round_trip(const std::string& text, Parse parse, Format format) {
  std::istringstream in(text);
  std::string written;
  try {
    written = format(parse(in, "fuzz.csv"));
  } catch (const Error&) {
    return;  // refused, or a session the writer cannot represent (named by an exception)
  }
  std::istringstream again(written);
  if (format(parse(again, "again.csv")) != written) std::abort();  // write-read must be exact
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  session_round_trip(text, parse_ballbar, format_ballbar);
  session_round_trip(text, parse_rtest, format_rtest);
  session_round_trip(text, parse_probe, format_probe);
  try {
    const ModelFile m = parse_model(text, "fuzz.json");
    // The writer never writes what the reader refuses.
    const std::string written = format_model(m.document, "fuzz.json");
    if (parse_model(written, "again.json").document != m.document) std::abort();
  } catch (const Error&) {
  }
  return 0;
}
