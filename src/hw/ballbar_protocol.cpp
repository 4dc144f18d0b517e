#include "rotacal/hw/ballbar_protocol.hpp"

#include <cmath>
#include <cstdlib>

#include "rotacal/core/error.hpp"

namespace rotacal::hw {

namespace {
constexpr std::size_t kSamplePayload = 11;

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}
}  // namespace

Bytes encode_ballbar_sample(const BallbarFrame& f) {
  Bytes p;
  p.reserve(kSamplePayload);
  put_u16(p, f.seq);
  put_u32(p, f.t_us);
  put_u32(p, static_cast<std::uint32_t>(f.displacement_nm));
  p.push_back(f.status);
  return encode_frame(kBallbarSampleFrame, p);
}

std::optional<BallbarFrame> decode_ballbar_sample(const Frame& f) {
  if (f.type != kBallbarSampleFrame || f.payload.size() != kSamplePayload) return std::nullopt;
  const std::uint8_t* p = f.payload.data();
  BallbarFrame s;
  s.seq = get_u16(p);
  s.t_us = get_u32(p + 2);
  s.displacement_nm = static_cast<std::int32_t>(get_u32(p + 6));
  s.status = p[10];
  return s;
}

Bytes encode_text(const std::string& text) {
  return encode_frame(kTextFrame, Bytes(text.begin(), text.end()));
}

std::optional<std::string> decode_text(const Frame& f) {
  if (f.type != kTextFrame) return std::nullopt;
  for (std::uint8_t c : f.payload)
    if (c < 0x20 || c > 0x7E) return std::nullopt;
  return std::string(f.payload.begin(), f.payload.end());
}

std::string format_command(BallbarCommand c, double rate_hz) {
  switch (c) {
    case BallbarCommand::start: return "START\n";
    case BallbarCommand::stop: return "STOP\n";
    case BallbarCommand::zero: return "ZERO\n";
    case BallbarCommand::identify: return "ID?\n";
    case BallbarCommand::rate: {
      if (!(rate_hz > 0.0) || rate_hz > 1000.0 || rate_hz != std::floor(rate_hz))
        throw InvalidArgument("ballbar rate: " + std::to_string(rate_hz) +
                              " Hz is not a whole number in 1..1000");
      return "RATE " + std::to_string(static_cast<int>(rate_hz)) + "\n";
    }
  }
  throw InvalidArgument("format_command: unknown command");
}

std::optional<BallbarCommandLine> parse_command(const std::string& raw) {
  const std::string line = trim(raw);
  if (line == "START") return BallbarCommandLine{BallbarCommand::start, 0.0};
  if (line == "STOP") return BallbarCommandLine{BallbarCommand::stop, 0.0};
  if (line == "ZERO") return BallbarCommandLine{BallbarCommand::zero, 0.0};
  if (line == "ID?") return BallbarCommandLine{BallbarCommand::identify, 0.0};
  if (line.rfind("RATE ", 0) == 0) {
    const std::string num = trim(line.substr(5));
    char* end = nullptr;
    const long hz = std::strtol(num.c_str(), &end, 10);
    if (num.empty() || *end != '\0' || hz < 1 || hz > 1000) return std::nullopt;
    return BallbarCommandLine{BallbarCommand::rate, static_cast<double>(hz)};
  }
  return std::nullopt;
}

}  // namespace rotacal::hw
