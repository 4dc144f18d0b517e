// Recorders: one stream reader for the ballbar and the probe stream, the polled probe loop (recorder.hpp).
#include "rotacal/hw/recorder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <optional>
#include <thread>

#include "rotacal/hw/ballbar_protocol.hpp"
#include "rotacal/hw/stream_protocol.hpp"
#include "rotacal/io/ballbar_file.hpp"

namespace rotacal::hw {

namespace {

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
  std::optional<double> advance(std::uint16_t seq, std::uint32_t t_us, Writer& out, RecordSummary& sum) {
    const double t = clock.seconds(t_us);
    if (last_seq) {
      const int gap = sequence_gap(*last_seq, seq);
      if (gap > 0) {
        sum.lost += static_cast<std::size_t>(gap);
        out.annotate("gap: " + std::to_string(gap) + " samples lost between seq " + std::to_string(*last_seq) +
                     " and " + std::to_string(seq) + " (t=" + fixed(last_t, 4) + ".." + fixed(t, 4) + " s)");
      }
    }
    last_seq = seq;
    if (t < last_t) {
      ++sum.malformed;
      out.annotate("malformed: sample time " + fixed(t, 6) + " s goes backwards (seq " + std::to_string(seq) + ")");
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
    garbage_since_data = scan.frames.empty() ? garbage_since_data + scan.garbage_bytes : scan.garbage_bytes;
    std::vector<Frame> out = std::move(backlog);
    backlog.clear();
    out.insert(out.end(), std::make_move_iterator(scan.frames.begin()), std::make_move_iterator(scan.frames.end()));
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

// Sends a command and waits for the text reply that starts with `expect`; other frames are
// ignored. Returns the error to stop with, if any.
std::optional<std::pair<StopReason, std::string>> handshake(ByteTransport& port, FrameReader& reader,
                                                            RecordSummary& sum, const std::string& command,
                                                            const std::string& expect, double timeout_s) {
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
        return std::make_pair(StopReason::no_valid_data, "the instrument refused '" + cmd + "': " + *text);
    }
  }
  ++sum.timeouts;
  if (sum.garbage_bytes > 0)
    return std::make_pair(StopReason::no_valid_data,
                          "no reply to '" + cmd + "' within " + fixed(timeout_s, 1) + " s, only " +
                              std::to_string(sum.garbage_bytes) +
                              " undecodable bytes: wrong baud rate or not this protocol?");
  return std::make_pair(StopReason::silence, "no reply to '" + cmd + "' within " + fixed(timeout_s, 1) + " s");
}

// ID?, [ZERO,] RATE, START. False (reason and detail in `sum`) if the instrument does not
// answer as it should; `guard` sends STOP later once START has gone out.
bool start_stream(ByteTransport& port, FrameReader& reader, RecordSummary& sum, const RecordOptions& opt,
                  bool zero, StreamGuard& guard) {
  auto fail = handshake(port, reader, sum, format_command(StreamCommand::identify), "ID ", 1.0);
  if (!fail && zero) fail = handshake(port, reader, sum, format_command(StreamCommand::zero), "OK ZERO", 1.0);
  if (!fail) fail = handshake(port, reader, sum, format_command(StreamCommand::rate, opt.rate_hz), "OK RATE", 1.0);
  if (!fail) {
    guard.active = true;
    fail = handshake(port, reader, sum, format_command(StreamCommand::start), "OK START", 1.0);
  }
  if (!fail) return true;
  sum.reason = fail->first;
  sum.detail = fail->second;
  return false;
}

// After each read of a stream: mark checksum failures in the file, and give up (true, reason
// no_valid_data) when too many bytes have passed without a valid frame.
template <typename Writer>
bool check_link(Writer& out, RecordSummary& sum, std::size_t new_crc, std::size_t garbage_since_data,
                double t, const RecordOptions& opt) {
  if (new_crc > 0)
    out.annotate("corrupt: " + std::to_string(new_crc) + " frames failed their checksum near t=" + fixed(t, 4) +
                 " s");
  if (garbage_since_data <= opt.max_garbage_without_data) return false;
  sum.reason = StopReason::no_valid_data;
  sum.detail = std::to_string(garbage_since_data) + " bytes without a valid frame: wrong baud rate or not this protocol?";
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

bool over_range(const BallbarFrame& s) { return (s.status & kStatusOverRange) != 0; }
bool over_range(const ProbeFrame& s) { return s.status != 0; }

// The one stream reader of both recorders: ID?, [ZERO,] RATE, START; then sample frames until
// END, silence, a dead link or a stop request, and STOP however it ends. Every valid sample
// goes to use(t, sample) with its unwrapped instrument time; sequence gaps, checksum errors,
// malformed frames, time going backwards and over-range readings are counted and marked in
// the file. Returns true at END (the instrument ran its program to the end).
template <typename Writer, typename Decode, typename Use>
bool read_stream(ByteTransport& port, const RecordOptions& opt, bool zero, Writer& out, RecordSummary& sum,
                 Decode decode, Use use, double duration) {
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
                       std::to_string(f.payload.size()) + " bytes near t=" + fixed(stream.last_t, 4) + " s");
          continue;
        }
        ++sum.frames;
        const auto t = stream.advance(s->seq, s->t_us, out, sum);
        if (!t) continue;
        if (over_range(*s)) {
          ++sum.over_range;
          out.annotate("over range: seq " + std::to_string(s->seq) + " at t=" + fixed(*t, 4) + " s");
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
// device), the file is closed with its summary line and keeps every row written.
template <typename Writer, typename Body>
RecordSummary run_recording(ByteTransport& port, Writer& out, Body body) {
  RecordSummary sum;
  try {
    port.flush_input();
    body(sum);
  } catch (const DeviceDisconnected& e) {
    sum.reason = StopReason::disconnected;
    sum.detail = e.what();
  }
  sum.rows = out.rows();
  out.annotate("summary: " + sum.describe());
  out.close();
  return sum;
}

}  // namespace

std::string to_string(StopReason r) {
  switch (r) {
    case StopReason::end_of_program: return "end of program";
    case StopReason::stopped: return "stopped";
    case StopReason::disconnected: return "device disconnected";
    case StopReason::silence: return "silence (timeout)";
    case StopReason::no_valid_data: return "no valid data";
  }
  return "?";
}

std::string RecordSummary::describe() const {
  std::string s = std::to_string(rows) + " rows; " + std::to_string(lost) + " lost, " +
                  std::to_string(crc_errors) + " checksum errors, " + std::to_string(malformed) +
                  " malformed, " + std::to_string(garbage_bytes) + " garbage bytes, " +
                  std::to_string(over_range) + " over range, " + std::to_string(timeouts) +
                  " timeouts; stopped: " + to_string(reason);
  if (!detail.empty()) s += " (" + detail + ")";
  return s;
}

// ---------------------------------------------------------------------------------- ballbar

RecordSummary record_ballbar(ByteTransport& port, const ProgramTimeline& program, const std::string& path,
                             const RecordOptions& opt) {
  BallbarSession header = program.header();
  header.metadata = {{"recorded_from", port.path()},
                     {"recorded_at", utc_now()},
                     {"sample_rate_hz", fixed(opt.rate_hz, 0)}};
  BallbarWriter out(path, header);
  const double L0 = header.ballbar_length;
  return run_recording(port, out, [&](RecordSummary& sum) {
    read_stream(port, opt, opt.zero, out, sum, decode_ballbar_sample,
                [&](double t, const BallbarFrame& s) {
                  BallbarSample row = program.at(t);
                  row.length = L0 + 1e-6 * s.displacement_nm;
                  out.append(row);
                },
                program.duration());
  });
}

// ---------------------------------------------------------------------------------- R-test

namespace {

// Averages the at-rest readings of each pose in program order and writes its row.
class PoseAverager {
 public:
  PoseAverager(const RtestSession& program, double dwell_s, RtestWriter& out, RecordSummary& sum)
      : program_(program), half_window_(0.25 * dwell_s), out_(out), summary_(sum) {}

  bool done() const { return next_ >= program_.samples.size(); }
  double window_start() const { return done() ? 1e300 : program_.samples[next_].time - half_window_; }
  double end_time() const { return program_.samples.back().time + half_window_; }

  /// A reading at program time t: pose(s) whose window ended before t are written first.
  void add(double t, const Eigen::Vector3d& r) {
    advance(t);
    if (done() || t < window_start()) return;
    sum_ += r;
    sum_sq_ += r.cwiseProduct(r);
    ++n_;
  }
  /// Write every pose whose window ends before t.
  void advance(double t) {
    while (!done() && t > program_.samples[next_].time + half_window_) write_pose();
  }

 private:
  void write_pose() {
    const RtestSample& p = program_.samples[next_];
    if (n_ == 0) {
      ++summary_.lost;
      out_.annotate("missing: pose " + std::to_string(next_ + 1) + " (set-up " + p.setup + ", B/A=" +
                    fixed(p.tilt_deg, 3) + ", C=" + fixed(p.rot_deg, 3) + "): no reading at rest");
    } else {
      RtestSample row = p;
      const Eigen::Vector3d mean = sum_ / static_cast<double>(n_);
      row.raw = mean;
      Eigen::Vector3d var = Eigen::Vector3d::Zero();
      if (n_ > 1)
        var = ((sum_sq_ - static_cast<double>(n_) * mean.cwiseProduct(mean)) / static_cast<double>(n_ - 1))
                  .cwiseMax(0.0);
      row.extra = {std::to_string(n_), fixed(1e3 * std::sqrt(var.maxCoeff()), 3)};
      out_.append(row);
    }
    ++next_;
    n_ = 0;
    sum_.setZero();
    sum_sq_.setZero();
  }
  const RtestSession& program_;
  double half_window_;
  RtestWriter& out_;
  RecordSummary& summary_;
  std::size_t next_ = 0;
  std::size_t n_ = 0;
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_sq_ = Eigen::Vector3d::Zero();
};

// One polled reading of all three channels; nullopt (and counted) if any channel failed.
// Reply lines across reads (a reply may arrive in pieces, or two at once).
struct LineReader {
  Bytes pending;
  std::vector<std::string> lines;  // complete, not yet taken
  std::size_t next = 0;
  std::optional<std::string> take(ByteTransport& port, RecordSummary& sum, int timeout_ms) {
    const double t_end = wall_seconds() + 1e-3 * timeout_ms;
    std::uint8_t buf[256];
    while (next >= lines.size()) {
      const double left = t_end - wall_seconds();
      if (left <= 0) return std::nullopt;
      const std::size_t n = port.read(buf, sizeof buf, std::max(1, static_cast<int>(1e3 * left)));
      pending.insert(pending.end(), buf, buf + n);
      LineScan scan = split_lines(pending.data(), pending.size());
      pending.erase(pending.begin(), pending.begin() + static_cast<long>(scan.consumed));
      sum.garbage_bytes += scan.garbage_bytes;
      lines.erase(lines.begin(), lines.begin() + static_cast<long>(next));
      next = 0;
      lines.insert(lines.end(), scan.lines.begin(), scan.lines.end());
    }
    return lines[next++];
  }
};

// One polled reading of all three channels; nullopt (and counted) if any channel failed.
std::optional<Eigen::Vector3d> poll_once(ByteTransport& port, ProbeMode mode, LineReader& lines,
                                         RecordSummary& sum, int timeout_ms) {
  auto read_line = [&] { return lines.take(port, sum, timeout_ms); };
  auto value_of = [&](const GaugeValue& v) -> std::optional<double> {
    if (v.ok()) return v.mm;
    if (v.kind == GaugeValue::Kind::error) ++sum.malformed;
    else ++sum.over_range;
    return std::nullopt;
  };
  Eigen::Vector3d r;
  if (mode == ProbeMode::keyence) {
    port.write(keyence_request(0), 200);
    const auto line = read_line();
    if (!line) return ++sum.timeouts, std::nullopt;
    const auto reply = parse_keyence_reply(*line);
    if (!reply) return ++sum.malformed, std::nullopt;
    if (reply->values.size() != 3) {
      value_of(reply->values.front());
      return std::nullopt;
    }
    for (int i = 0; i < 3; ++i) {
      const auto v = value_of(reply->values[static_cast<std::size_t>(i)]);
      if (!v) return std::nullopt;
      r[i] = *v;
    }
  } else {
    for (int ch = 1; ch <= 3; ++ch) {
      port.write(sylvac_request(ch), 200);
      const auto line = read_line();
      if (!line) return ++sum.timeouts, std::nullopt;
      const auto reply = parse_sylvac_reply(*line);
      if (!reply) return ++sum.malformed, std::nullopt;
      const auto v = value_of(*reply);
      if (!v) return std::nullopt;
      r[ch - 1] = *v;
    }
  }
  ++sum.frames;
  return r;
}

}  // namespace

RecordSummary record_rtest(ByteTransport& port, ProbeMode mode, const RtestSession& program, double dwell_s,
                           const Eigen::Matrix3d& probe_dirs, const std::string& path,
                           const RecordOptions& opt) {
  if (program.samples.empty()) throw InvalidArgument("record_rtest: the program has no poses");
  if (!(dwell_s > 0.0)) throw InvalidArgument("record_rtest: dwell_s must be positive");
  RtestSession header = program;
  header.samples.clear();
  header.noise_um.reset();  // what the program was simulated with is not what was measured
  header.extra_columns = {"n", "std_um"};
  header.metadata = {{"recorded_from", port.path()},
                     {"recorded_at", utc_now()},
                     {"probe_mode", to_string(mode)}};
  header.probe_dirs.clear();
  for (int k = 0; k < 3; ++k) header.probe_dirs[k + 1] = probe_dirs.row(k).transpose();
  RtestWriter out(path, header, /*raw=*/true);
  return run_recording(port, out, [&](RecordSummary& sum) {
    PoseAverager poses(program, dwell_s, out, sum);
    if (mode == ProbeMode::stream) {
      const bool ended = read_stream(
          port, opt, false, out, sum, decode_probe_sample,
          [&](double t, const ProbeFrame& s) {
            poses.add(t, Eigen::Vector3d(1e-6 * s.nm[0], 1e-6 * s.nm[1], 1e-6 * s.nm[2]));
          },
          poses.end_time());
      if (ended) poses.advance(1e300);
      return;
    }
    // Polled: the host clock paces the program; the instrument starts it at our first request.
    ProgressGate progress(opt);
    LineReader lines;
    const double t0 = wall_seconds();
    std::size_t failures_in_row = 0;
    for (;;) {
      const double t_req = (wall_seconds() - t0) * opt.speed;
      const auto r = poll_once(port, mode, lines, sum, opt.read_timeout_ms);
      const double t = 0.5 * (t_req + (wall_seconds() - t0) * opt.speed);
      if (r) {
        failures_in_row = 0;
        poses.add(t, *r);
      } else if (++failures_in_row * static_cast<std::size_t>(opt.read_timeout_ms) >
                     static_cast<std::size_t>(1e3 * opt.silence_timeout_s) &&
                 sum.timeouts > 0) {
        sum.reason = sum.garbage_bytes > 0 ? StopReason::no_valid_data : StopReason::silence;
        sum.detail = "no valid reply for " + fixed(opt.silence_timeout_s, 1) + " s";
        return;
      }
      poses.advance(t);
      if (poses.done()) {
        sum.reason = StopReason::end_of_program;
        return;
      }
      if (!progress(out.rows(), sum, t, poses.end_time())) {
        sum.reason = StopReason::stopped;
        return;
      }
      // Sleep until the next pose's window if it is far ahead; else poll again soon.
      const double wait = (poses.window_start() - (wall_seconds() - t0) * opt.speed) / opt.speed;
      std::this_thread::sleep_for(std::chrono::duration<double>(std::clamp(wait, 0.002, 0.05)));
    }
  });
}

}  // namespace rotacal::hw
