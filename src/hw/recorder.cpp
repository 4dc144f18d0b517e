// Recorders: one stream reader for the ballbar and the probe stream, the polled probe loop (recorder.hpp).
#include "rotacal/hw/recorder.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <optional>
#include <thread>

#include "rotacal/hw/ballbar_protocol.hpp"
#include "rotacal/hw/pose_window.hpp"
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
                  std::to_string(over_range) + " over range, " + std::to_string(timeouts) + " timeouts";
  if (outside_window > 0) s += ", " + std::to_string(outside_window) + " polled readings outside their pose's window";
  s += "; stopped: " + to_string(reason);
  if (!detail.empty()) s += " (" + detail + ")";
  return s;
}

// ---------------------------------------------------------------------------------- ballbar

namespace {

// A ballbar recording against any program with header(), at(t) and duration().
template <typename Program>
RecordSummary record_ballbar_program(ByteTransport& port, const Program& program,
                                     const std::string& path, const RecordOptions& opt) {
  BallbarSession header = program.header();
  header.metadata = {{"recorded_from", port.path()},
                     {"recorded_at", utc_now()},
                     {"sample_rate_hz", fixed(opt.rate_hz, 0)}};
  BallbarWriter out(path, header, OutputOptions{{port.path()}, {}});
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

}  // namespace

RecordSummary record_ballbar(ByteTransport& port, const ProgramTimeline& program, const std::string& path,
                             const RecordOptions& opt) {
  return record_ballbar_program(port, program, path, opt);
}

RecordSummary record_ballbar(ByteTransport& port, const CircularTimeline& program,
                             const std::string& path, const RecordOptions& opt) {
  return record_ballbar_program(port, program, path, opt);
}

// ---------------------------------------------------------------------------------- R-test

namespace {

// Averages the readings of each pose taken inside its read window (pose_window.hpp), in
// program order, and writes its row with the readings' mean time and smallest margin. A
// polled reading that may have been taken outside the window is counted and marked, not used;
// a pose without a reading inside its window is counted lost and marked.
class PoseAverager {
 public:
  PoseAverager(const RtestSession& program, double dwell_s, RtestWriter& out, RecordSummary& sum)
      : program_(program), dwell_s_(dwell_s), out_(out), summary_(sum) {}

  bool done() const { return next_ >= program_.samples.size(); }
  /// The read window of the next pose to be written.
  PoseWindow window() const { return pose_window(program_.samples[next_].time, dwell_s_); }
  double end_time() const { return pose_window(program_.samples.back().time, dwell_s_).end; }

  /// A reading taken somewhere in program time [a, b] (a == b for a timestamped stream sample).
  /// Poses whose window ended before a are written first. `polled`: a reading that is not
  /// surely inside the window is marked; stream samples between windows (the table moving) are
  /// simply not used.
  void add(double a, double b, const Eigen::Vector3d& r, bool polled) {
    advance(a);
    if (done()) return;
    const PoseWindow w = window();
    if (!w.contains(a, b)) {
      if (polled) {
        ++outside_;
        worst_outside_ = std::min(worst_outside_, w.margin(a, b));
      }
      return;
    }
    sum_ += r;
    sum_sq_ += r.cwiseProduct(r);
    t_sum_ += 0.5 * (a + b);
    margin_ = std::min(margin_, w.margin(a, b));
    ++n_;
  }
  /// Write every pose whose window surely ended before program time t.
  void advance(double t) {
    while (!done() && t > window().end) write_pose();
  }
  /// The host could not take a reading in program time [a, b]: it did not run (between two
  /// passes of its loop) or was waiting for a reply. Kept so that a pose lost to a late host
  /// says for how long of its window that was.
  void host_unavailable(double a, double b) {
    if (b > a && !done() && b > window().begin) unavailable_.emplace_back(a, b);
  }
  /// How long, program s, one reading typically takes the host now (RoundTrips).
  void reading_takes(double s) { reading_takes_ = s; }
  bool has_reading() const { return n_ > 0; }

 private:
  void write_pose() {
    const RtestSample& p = program_.samples[next_];
    const PoseWindow w = window();
    const std::string pose = "pose " + std::to_string(next_ + 1) + " (set-up " + p.setup + ", B/A=" +
                             fixed(p.tilt_deg, 3) + ", C=" + fixed(p.rot_deg, 3) + ")";
    const std::string span = "[" + fixed(w.begin, 3) + ", " + fixed(w.end, 3) + "] s";
    const std::string late = std::to_string(outside_) + " reading" + (outside_ == 1 ? "" : "s") +
                             " not surely inside it (margin down to " + fixed(worst_outside_, 3) + " s)";
    summary_.outside_window += outside_;
    if (n_ == 0) {
      ++summary_.lost;
      // The longest stretch of the window in which the host could not read.
      double longest = 0.0;
      std::pair<double, double> when;
      for (const auto& [a, b] : unavailable_) {
        const double overlap = std::min(w.end, b) - std::max(w.begin, a);
        if (overlap > longest) longest = overlap, when = {a, b};
      }
      const std::string idle = (longest > 0.0 ? "; the host could not read for " + fixed(longest, 3) + " s of it (" +
                                                    fixed(when.first, 3) + " to " + fixed(when.second, 3) + " s)"
                                              : std::string()) +
                               "; a reading took the host " + fixed(reading_takes_, 3) + " s";
      out_.annotate("missing: " + pose + ": no reading inside its window " + span + idle +
                    (outside_ > 0 ? "; " + late : ""));
    } else {
      if (outside_ > 0) out_.annotate("outside: " + pose + ", window " + span + ": " + late + ", not used");
      RtestSample row = p;
      const double n = static_cast<double>(n_);
      const Eigen::Vector3d mean = sum_ / n;
      row.raw = mean;
      Eigen::Vector3d var = Eigen::Vector3d::Zero();
      if (n_ > 1) var = ((sum_sq_ - n * mean.cwiseProduct(mean)) / (n - 1.0)).cwiseMax(0.0);
      row.extra = {std::to_string(n_), fixed(1e3 * std::sqrt(var.maxCoeff()), 3), fixed(t_sum_ / n, 4),
                   fixed(margin_, 4)};
      out_.append(row);
    }
    ++next_;
    n_ = 0;
    outside_ = 0;
    sum_.setZero();
    sum_sq_.setZero();
    t_sum_ = 0.0;
    margin_ = worst_outside_ = std::numeric_limits<double>::infinity();
    if (!done()) {  // keep what may still overlap the next window (a stall may span several)
      const double begin = window().begin;
      unavailable_.erase(std::remove_if(unavailable_.begin(), unavailable_.end(),
                                        [&](const std::pair<double, double>& u) { return u.second <= begin; }),
                         unavailable_.end());
    }
  }
  const RtestSession& program_;
  double dwell_s_;
  RtestWriter& out_;
  RecordSummary& summary_;
  std::size_t next_ = 0;
  std::size_t n_ = 0;
  std::size_t outside_ = 0;
  Eigen::Vector3d sum_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_sq_ = Eigen::Vector3d::Zero();
  double t_sum_ = 0.0;
  double margin_ = std::numeric_limits<double>::infinity();
  double worst_outside_ = std::numeric_limits<double>::infinity();
  std::vector<std::pair<double, double>> unavailable_;  ///< program s, since this window began
  double reading_takes_ = 0.0;
};

// The program clock of a polled instrument as the host knows it. The instrument starts it
// when our first request reaches it: after we sent that request, before its reply came back.
// A host wall time w is therefore program time in [(w - replied) speed, (w - sent) speed].
struct ProgramClock {
  double sent = 0.0;
  double replied = 0.0;
  double speed = 1.0;
  double earliest(double wall) const { return (wall - replied) * speed; }
  double latest(double wall) const { return (wall - sent) * speed; }
};

// The typical (median) of the last 15 request-to-reply times, wall s: how long the host may
// expect a reading to take. A median, so that one stall does not stop the host from reading.
class RoundTrips {
 public:
  void add(double s) {
    last_[next_++ % last_.size()] = s;
    count_ = std::min(count_ + 1, last_.size());
  }
  double typical() const {
    if (count_ == 0) return 0.0;
    std::array<double, 15> v = last_;
    std::nth_element(v.begin(), v.begin() + static_cast<long>(count_ / 2), v.begin() + static_cast<long>(count_));
    return v[count_ / 2];
  }

 private:
  std::array<double, 15> last_{};
  std::size_t next_ = 0;
  std::size_t count_ = 0;
};

// Reply lines across reads (a reply may arrive in pieces, or two at once).
struct LineReader {
  Bytes pending;
  std::vector<std::string> lines;  // complete, not yet taken
  std::size_t next = 0;
  std::size_t taken = 0;  // lines returned so far
  /// The next reply line. Each read_timeout_ms without one counts as a timeout; nullopt after
  /// give_up_s (the device is silent).
  std::optional<std::string> take(ByteTransport& port, RecordSummary& sum, int read_timeout_ms, double give_up_s) {
    const double t_end = wall_seconds() + give_up_s;
    std::uint8_t buf[256];
    while (next >= lines.size()) {
      const double left = t_end - wall_seconds();
      if (left <= 0) return std::nullopt;
      const std::size_t n = port.read(buf, sizeof buf, std::clamp(static_cast<int>(1e3 * left), 1, read_timeout_ms));
      if (n == 0) {
        ++sum.timeouts;
        continue;
      }
      pending.insert(pending.end(), buf, buf + n);
      LineScan scan = split_lines(pending.data(), pending.size());
      pending.erase(pending.begin(), pending.begin() + static_cast<long>(scan.consumed));
      sum.garbage_bytes += scan.garbage_bytes;
      lines.erase(lines.begin(), lines.begin() + static_cast<long>(next));
      next = 0;
      lines.insert(lines.end(), scan.lines.begin(), scan.lines.end());
    }
    ++taken;
    return lines[next++];
  }
};

struct Poll {
  std::optional<Eigen::Vector3d> reading;  ///< nullopt (and counted) if any channel failed
  bool silent = false;                     ///< a request went unanswered for silence_timeout_s
};

// One polled reading of all three channels. A polled device answers every request once, so
// the host waits for that answer (however late) rather than asking again: a second request
// would pair every later reply with the wrong request, and the wrong time.
Poll poll_once(ByteTransport& port, ProbeMode mode, LineReader& lines, RecordSummary& sum, const RecordOptions& opt) {
  auto ask = [&](const std::string& request) {
    port.write(request, 200);
    return lines.take(port, sum, opt.read_timeout_ms, opt.silence_timeout_s);
  };
  auto value_of = [&](const GaugeValue& v) -> std::optional<double> {
    if (v.ok()) return v.mm;
    if (v.kind == GaugeValue::Kind::error) ++sum.malformed;
    else ++sum.over_range;
    return std::nullopt;
  };
  Poll failed;
  Eigen::Vector3d r;
  if (mode == ProbeMode::keyence) {
    const auto line = ask(keyence_request(0));
    if (!line) return failed.silent = true, failed;
    const auto reply = parse_keyence_reply(*line);
    if (!reply) return ++sum.malformed, failed;
    if (reply->values.size() != 3) {
      value_of(reply->values.front());
      return failed;
    }
    for (int i = 0; i < 3; ++i) {
      const auto v = value_of(reply->values[static_cast<std::size_t>(i)]);
      if (!v) return failed;
      r[i] = *v;
    }
  } else {
    for (int ch = 1; ch <= 3; ++ch) {
      const auto line = ask(sylvac_request(ch));
      if (!line) return failed.silent = true, failed;
      const auto reply = parse_sylvac_reply(*line);
      if (!reply) return ++sum.malformed, failed;
      const auto v = value_of(*reply);
      if (!v) return failed;
      r[ch - 1] = *v;
    }
  }
  ++sum.frames;
  return Poll{r, false};
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
  header.extra_columns = {"n", "std_um", "t_s", "margin_s"};
  header.metadata = {{"recorded_from", port.path()},
                     {"recorded_at", utc_now()},
                     {"probe_mode", to_string(mode)}};
  header.probe_dirs.clear();
  for (int k = 0; k < 3; ++k) header.probe_dirs[k + 1] = probe_dirs.row(k).transpose();
  RtestWriter out(path, header, /*raw=*/true, OutputOptions{{port.path()}, {}});
  return run_recording(port, out, [&](RecordSummary& sum) {
    PoseAverager poses(program, dwell_s, out, sum);
    if (mode == ProbeMode::stream) {
      const bool ended = read_stream(
          port, opt, false, out, sum, decode_probe_sample,
          [&](double t, const ProbeFrame& s) {
            poses.add(t, t, Eigen::Vector3d(1e-6 * s.nm[0], 1e-6 * s.nm[1], 1e-6 * s.nm[2]), false);
          },
          poses.end_time());
      if (ended) poses.advance(1e300);
      return;
    }
    // Polled: each reading is placed by the interval from its first request to its last reply,
    // in program time as far as the clock is known (ProgramClock). The host reads while the
    // next pose is surely in its window and a round trip still fits; a pose is written once its
    // window has surely passed.
    ProgressGate progress(opt);
    LineReader lines;
    std::optional<ProgramClock> clock;
    const double first_sent = wall_seconds();
    RoundTrips round_trips;
    auto pause = [](double s) { std::this_thread::sleep_for(std::chrono::duration<double>(std::clamp(s, 0.001, 0.05))); };
    double last_ran = first_sent;  // when the loop last ran, wall s
    for (;;) {
      if (clock) {
        const double now = wall_seconds();
        const double early = clock->earliest(now), late = clock->latest(now);
        poses.host_unavailable(clock->latest(last_ran), early);
        last_ran = now;
        poses.advance(early);
        if (poses.done()) {
          sum.reason = StopReason::end_of_program;
          return;
        }
        if (!progress(out.rows(), sum, late, poses.end_time())) {
          sum.reason = StopReason::stopped;
          return;
        }
        // Read only while the next pose is surely in its window and a reading still fits: a
        // first one if one typical reading does, more while three do (and 5 % of the window).
        const PoseWindow w = poses.window();
        const double takes = round_trips.typical() * opt.speed;
        poses.reading_takes(takes);
        const double guard = poses.has_reading() ? std::max(3.0 * takes, 0.05 * (w.end - w.begin)) : takes;
        if (early < w.begin) {
          pause((w.begin - early) / opt.speed);
          continue;
        }
        if (late + guard > w.end) {
          pause((w.end - early) / opt.speed + 1e-3);  // until it has surely passed: written then
          continue;
        }
      }
      const double sent = wall_seconds();
      const std::size_t taken = lines.taken;
      const Poll poll = poll_once(port, mode, lines, sum, opt);
      const double received = wall_seconds();
      if (poll.silent) {
        sum.reason = sum.garbage_bytes > 0 ? StopReason::no_valid_data : StopReason::silence;
        sum.detail = "no valid reply for " + fixed(opt.silence_timeout_s, 1) + " s";
        return;
      }
      if (!clock && lines.taken > taken) clock = ProgramClock{first_sent, received, opt.speed};
      round_trips.add(received - sent);
      if (clock) poses.host_unavailable(clock->latest(sent), clock->earliest(received));
      if (poll.reading && clock) poses.add(clock->earliest(sent), clock->latest(received), *poll.reading, true);
      last_ran = wall_seconds();
      pause(0.002);  // between readings inside a window
    }
  });
}

}  // namespace rotacal::hw
