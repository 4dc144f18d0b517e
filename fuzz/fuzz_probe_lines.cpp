// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: the ASCII probe dialects (line splitter, sylvac-style and keyence-style
// replies, device-side request parsers) must accept any bytes without crashing, and a reply
// they accept must survive format -> parse unchanged in kind.
#include <cstdlib>
#include <string>

#include "rotacal/hw/ballbar_protocol.hpp"
#include "rotacal/hw/probe_protocol.hpp"

using namespace rotacal::hw;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const LineScan s = split_lines(data, size);
  if (s.consumed > size) std::abort();
  for (const std::string& line : s.lines) {
    if (const auto v = parse_sylvac_reply(line)) {
      const std::string again = format_sylvac_reply(*v);
      const auto w = parse_sylvac_reply(again.substr(0, again.size() - 1));
      if (!w || (w->kind != v->kind && v->kind != GaugeValue::Kind::under_range)) std::abort();
    }
    if (const auto k = parse_keyence_reply(line)) {
      const std::string again = format_keyence_reply(*k);
      const auto w = parse_keyence_reply(again.substr(0, again.size() - 1));
      if (!w || w->values.size() != k->values.size()) std::abort();
    }
    (void)parse_sylvac_request(line);
    (void)parse_keyence_request(line);
    (void)parse_command(line);
  }
  return 0;
}
