// SPDX-License-Identifier: BSD-3-Clause
// What both instrument streams share: command lines, text reply frames (stream_protocol.hpp).
#include "rotacal/hw/stream_protocol.hpp"

#include <cmath>
#include <cstdlib>

#include "rotacal/core/error.hpp"

namespace rotacal::hw {

namespace {
std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}
}  // namespace

Bytes encode_text(const std::string& text) {
  return encode_frame(kTextFrame, Bytes(text.begin(), text.end()));
}

std::optional<std::string> decode_text(const Frame& f) {
  if (f.type != kTextFrame) return std::nullopt;
  for (std::uint8_t c : f.payload)
    if (c < 0x20 || c > 0x7E) return std::nullopt;
  return std::string(f.payload.begin(), f.payload.end());
}

std::string format_command(StreamCommand c, double rate_hz) {
  switch (c) {
    case StreamCommand::start:
      return "START\n";
    case StreamCommand::stop:
      return "STOP\n";
    case StreamCommand::zero:
      return "ZERO\n";
    case StreamCommand::identify:
      return "ID?\n";
    case StreamCommand::rate: {
      if (!(rate_hz > 0.0) || rate_hz > 1000.0 || rate_hz != std::floor(rate_hz))
        throw InvalidArgument("stream rate: " + std::to_string(rate_hz) +
                              " Hz is not a whole number in 1..1000");
      return "RATE " + std::to_string(static_cast<int>(rate_hz)) + "\n";
    }
  }
  throw InvalidArgument("format_command: unknown command");
}

std::optional<StreamCommandLine> parse_command(const std::string& raw) {
  const std::string line = trim(raw);
  if (line == "START") return StreamCommandLine{StreamCommand::start, 0.0};
  if (line == "STOP") return StreamCommandLine{StreamCommand::stop, 0.0};
  if (line == "ZERO") return StreamCommandLine{StreamCommand::zero, 0.0};
  if (line == "ID?") return StreamCommandLine{StreamCommand::identify, 0.0};
  if (line.rfind("RATE ", 0) == 0) {
    const std::string num = trim(line.substr(5));
    char* end = nullptr;
    const long hz = std::strtol(num.c_str(), &end, 10);
    if (num.empty() || *end != '\0' || hz < 1 || hz > 1000) return std::nullopt;
    return StreamCommandLine{StreamCommand::rate, static_cast<double>(hz)};
  }
  return std::nullopt;
}

}  // namespace rotacal::hw
