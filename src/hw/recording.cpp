// SPDX-License-Identifier: BSD-3-Clause
// What the recorders share (recording.hpp): clocks, the handshake and the start of a stream.
#include "recording.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>

namespace rotacal::hw::recording {

double wall_seconds() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

std::string fixed(double v, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

namespace {

// Sends a command and waits for the text reply that starts with `expect`; other frames are
// ignored. Returns the error to stop with, if any.
std::optional<std::pair<StopReason, std::string>> handshake(ByteTransport& port,
                                                            FrameReader& reader, RecordSummary& sum,
                                                            const std::string& command,
                                                            const std::string& expect,
                                                            double timeout_s) {
  port.write(command, 500);
  const double t_end = wall_seconds() + timeout_s;
  std::uint8_t buf[512];
  std::size_t garbage = 0, crc = 0;
  std::string cmd = command.substr(0, command.size() - 1);
  while (wall_seconds() < t_end) {
    const std::size_t n = port.read(buf, sizeof buf, 50);
    std::vector<Frame> frames = reader.feed(buf, n, sum, garbage, crc);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const auto text = decode_text(frames[i]);
      if (!text) continue;  // a sample before the reply (e.g. a stream still running): stale
      if (text->rfind(expect, 0) == 0) {
        // Samples behind the reply are the new stream's first: keep them for the caller.
        reader.backlog.assign(frames.begin() + static_cast<long>(i) + 1, frames.end());
        return std::nullopt;
      }
      if (text->rfind("ERR", 0) == 0)
        return std::make_pair(StopReason::no_valid_data,
                              "the instrument refused '" + cmd + "': " + *text);
    }
  }
  ++sum.timeouts;
  if (sum.garbage_bytes > 0)
    return std::make_pair(StopReason::no_valid_data,
                          "no reply to '" + cmd + "' within " + fixed(timeout_s, 1) + " s, only " +
                              std::to_string(sum.garbage_bytes) +
                              " undecodable bytes: wrong baud rate or not this protocol?");
  return std::make_pair(StopReason::silence,
                        "no reply to '" + cmd + "' within " + fixed(timeout_s, 1) + " s");
}

}  // namespace

bool start_stream(ByteTransport& port, FrameReader& reader, RecordSummary& sum,
                  const RecordOptions& opt, bool zero, StreamGuard& guard) {
  // A reply is awaited as long as the user waits for a silent instrument (--silence): a fixed
  // 1 s stopped a recording whose instrument (or host) was slow to answer under load.
  const double wait_s = opt.silence_timeout_s;
  auto fail = handshake(port, reader, sum, format_command(StreamCommand::identify), "ID ", wait_s);
  if (!fail && zero)
    fail = handshake(port, reader, sum, format_command(StreamCommand::zero), "OK ZERO", wait_s);
  if (!fail)
    fail = handshake(port, reader, sum, format_command(StreamCommand::rate, opt.rate_hz), "OK RATE",
                     wait_s);
  if (!fail) {
    guard.active = true;
    fail = handshake(port, reader, sum, format_command(StreamCommand::start), "OK START", wait_s);
  }
  if (!fail) return true;
  sum.reason = fail->first;
  sum.detail = fail->second;
  return false;
}

}  // namespace rotacal::hw::recording
