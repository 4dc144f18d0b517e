// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The one stream reader of both recorders (recorder.cpp: ballbar, record_rtest.cpp: the probe
// stream) and what a recording shares: host clock, device clock, frames across reads, the
// handshake, progress, and a recording that keeps every row written however it ends.
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rotacal/hw/ballbar_protocol.hpp"
#include "rotacal/hw/frame.hpp"
#include "rotacal/hw/probe_protocol.hpp"
#include "rotacal/hw/recorder.hpp"
#include "rotacal/hw/stream_protocol.hpp"

namespace rotacal::hw::recording {

double wall_seconds();
std::string utc_now();
std::string fixed(double v, int digits);

// Unwraps the 32-bit microsecond clock of a stream (wraps every 71.6 minutes).
struct DeviceClock {
  std::optional<std::uint32_t> last;
  std::uint64_t wraps = 0;
  double seconds(std::uint32_t t_us) {
    if (last && t_us < *last && *last - t_us > 0x80000000u) ++wraps;
    last = t_us;
    return (static_cast<double>(wraps) * 4294967296.0 + t_us) * 1e-6;
  }
};

// Where a stream is: unwrapped time and last sequence number. A jump in sequence numbers is
// counted and marked in the file; a sample whose time goes backwards is refused.
struct StreamPosition {
  DeviceClock clock;
  std::optional<std::uint16_t> last_seq;
  double last_t = 0.0;

  template <typename Writer>
  std::optional<double> advance(std::uint16_t seq, std::uint32_t t_us, Writer& out,
                                RecordSummary& sum) {
    const double t = clock.seconds(t_us);
    if (last_seq) {
      const int gap = sequence_gap(*last_seq, seq);
      if (gap > 0) {
        sum.lost += static_cast<std::size_t>(gap);
        out.annotate("gap: " + std::to_string(gap) + " samples lost between seq " +
                     std::to_string(*last_seq) + " and " + std::to_string(seq) +
                     " (t=" + fixed(last_t, 4) + ".." + fixed(t, 4) + " s)");
      }
    }
    last_seq = seq;
    if (t < last_t) {
      ++sum.malformed;
      out.annotate("malformed: sample time " + fixed(t, 6) + " s goes backwards (seq " +
                   std::to_string(seq) + ")");
      return std::nullopt;
    }
    last_t = t;
    return t;
  }
};

// Bytes in, frames out across reads; counts what it had to skip.
struct FrameReader {
  Bytes pending;
  std::vector<Frame> backlog;  ///< frames that arrived behind a handshake reply
  std::vector<Frame> feed(const std::uint8_t* data, std::size_t n, RecordSummary& sum,
                          std::size_t& garbage_since_data, std::size_t& new_crc) {
    pending.insert(pending.end(), data, data + n);
    FrameScan scan = scan_frames(pending.data(), pending.size());
    pending.erase(pending.begin(), pending.begin() + static_cast<long>(scan.consumed));
    sum.garbage_bytes += scan.garbage_bytes;
    sum.crc_errors += scan.crc_errors;
    new_crc = scan.crc_errors;
    garbage_since_data =
        scan.frames.empty() ? garbage_since_data + scan.garbage_bytes : scan.garbage_bytes;
    std::vector<Frame> out = std::move(backlog);
    backlog.clear();
    out.insert(out.end(), std::make_move_iterator(scan.frames.begin()),
               std::make_move_iterator(scan.frames.end()));
    return out;
  }
};

// Sends STOP when a streamed recording ends, however it ends (best effort: the line may be gone).
struct StreamGuard {
  ByteTransport& port;
  bool active = false;
  ~StreamGuard() {
    if (!active) return;
    try {
      port.write(format_command(StreamCommand::stop), 200);
    } catch (const std::exception&) {
    }
  }
};

// ID?, [ZERO,] RATE, START. False (reason and detail in `sum`) if the instrument does not
// answer as it should; `guard` sends STOP later once START has gone out.
bool start_stream(ByteTransport& port, FrameReader& reader, RecordSummary& sum,
                  const RecordOptions& opt, bool zero, StreamGuard& guard);

// After each read of a stream: mark checksum failures in the file, and give up (true, reason
// no_valid_data) when too many bytes have passed without a valid frame.
template <typename Writer>
bool check_link(Writer& out, RecordSummary& sum, std::size_t new_crc,
                std::size_t garbage_since_data, double t, const RecordOptions& opt) {
  if (new_crc > 0)
    out.annotate("corrupt: " + std::to_string(new_crc) +
                 " frames failed their checksum near t=" + fixed(t, 4) + " s");
  if (garbage_since_data <= opt.max_garbage_without_data) return false;
  sum.reason = StopReason::no_valid_data;
  sum.detail = std::to_string(garbage_since_data) +
               " bytes without a valid frame: wrong baud rate or not this protocol?";
  return true;
}

// The progress callback, at most every progress_interval_s; false when it asks to stop.
class ProgressGate {
 public:
  explicit ProgressGate(const RecordOptions& opt) : opt_(opt) {}
  bool operator()(std::size_t rows, const RecordSummary& sum, double t, double duration) {
    if (!opt_.progress) return true;
    const double now = wall_seconds();
    if (now - last_ < opt_.progress_interval_s) return true;
    last_ = now;
    return opt_.progress({rows, sum.lost, sum.crc_errors + sum.malformed, t, duration});
  }

 private:
  const RecordOptions& opt_;
  double last_ = 0.0;
};

inline bool over_range(const BallbarFrame& s) { return (s.status & kStatusOverRange) != 0; }
inline bool over_range(const ProbeFrame& s) { return s.status != 0; }

// The one stream reader of both recorders: ID?, [ZERO,] RATE, START; then sample frames until
// END, silence, a dead link or a stop request, and STOP however it ends. Every valid sample
// goes to use(t, sample) with its unwrapped instrument time; sequence gaps, checksum errors,
// malformed frames, time going backwards and over-range readings are counted and marked in
// the file. Returns true at END (the instrument ran its program to the end).
template <typename Writer, typename Decode, typename Use>
bool read_stream(ByteTransport& port, const RecordOptions& opt, bool zero, Writer& out,
                 RecordSummary& sum, Decode decode, Use use, double duration) {
  FrameReader reader;
  StreamGuard guard{port};
  try {
    if (!start_stream(port, reader, sum, opt, zero, guard)) return false;
    StreamPosition stream;
    ProgressGate progress(opt);
    double last_data = wall_seconds();
    std::size_t garbage_since_data = 0;
    std::uint8_t buf[4096];
    for (;;) {
      const std::size_t n = port.read(buf, sizeof buf, opt.read_timeout_ms);
      const double now = wall_seconds();
      if (n == 0) {
        ++sum.timeouts;
        if (now - last_data > opt.silence_timeout_s) {
          sum.reason = StopReason::silence;
          sum.detail = "nothing for " + fixed(opt.silence_timeout_s, 1) + " s";
          return false;
        }
      } else {
        last_data = now;
      }
      std::size_t new_crc = 0;
      bool ended = false;
      for (const Frame& f : reader.feed(buf, n, sum, garbage_since_data, new_crc)) {
        if (const auto text = decode_text(f)) {
          ended = ended || *text == "END";
          continue;
        }
        const auto s = decode(f);
        if (!s) {
          ++sum.malformed;
          out.annotate("malformed: frame of type " + std::to_string(f.type) + " and " +
                       std::to_string(f.payload.size()) +
                       " bytes near t=" + fixed(stream.last_t, 4) + " s");
          continue;
        }
        ++sum.frames;
        const auto t = stream.advance(s->seq, s->t_us, out, sum);
        if (!t) continue;
        if (over_range(*s)) {
          ++sum.over_range;
          out.annotate("over range: seq " + std::to_string(s->seq) + " at t=" + fixed(*t, 4) +
                       " s");
          continue;
        }
        use(*t, *s);
      }
      const bool link_lost = check_link(out, sum, new_crc, garbage_since_data, stream.last_t, opt);
      if (ended) {
        sum.reason = StopReason::end_of_program;
        guard.active = false;
        return true;
      }
      if (link_lost) return false;
      if (!progress(out.rows(), sum, stream.last_t, duration)) {
        sum.reason = StopReason::stopped;
        return false;
      }
    }
  } catch (const DeviceDisconnected&) {
    guard.active = false;  // no STOP down a dead line
    throw;
  }
}

// Runs a recording into `out`: whatever stops it (the end, a stop request, an unplugged
// device), the file is closed with its summary line and keeps every row written. A recording
// that ends with no row measured nothing: the target is left as it was (a previous session
// of that name stays), as after any failed write.
template <typename Writer, typename Body>
RecordSummary run_recording(ByteTransport& port, Writer& out, Body body) {
  RecordSummary sum;
  try {
    port.flush_input();
    body(sum);
  } catch (const DeviceDisconnected& e) {
    sum.reason = StopReason::disconnected;
    sum.detail = e.what();
  } catch (...) {
    if (out.rows() == 0) out.discard();
    throw;
  }
  sum.rows = out.rows();
  if (sum.rows == 0) {
    out.discard();
    return sum;
  }
  out.annotate("summary: " + sum.describe());
  out.close();
  return sum;
}

}  // namespace rotacal::hw::recording
