// SPDX-License-Identifier: BSD-3-Clause
// The R-test recorder: the probe stream through the shared stream reader (recording.hpp), or
// the polled probe loop, averaging each pose's readings inside its read window.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>

#include "recording.hpp"
#include "rotacal/hw/pose_window.hpp"
#include "rotacal/io/ballbar_file.hpp"

namespace rotacal::hw {

using namespace recording;

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
    const std::string pose = "pose " + std::to_string(next_ + 1) + " (set-up " + p.setup +
                             ", B/A=" + fixed(p.tilt_deg, 3) + ", C=" + fixed(p.rot_deg, 3) + ")";
    const std::string span = "[" + fixed(w.begin, 3) + ", " + fixed(w.end, 3) + "] s";
    const std::string late = std::to_string(outside_) + " reading" + (outside_ == 1 ? "" : "s") +
                             " not surely inside it (margin down to " + fixed(worst_outside_, 3) +
                             " s)";
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
      const std::string idle =
          (longest > 0.0 ? "; the host could not read for " + fixed(longest, 3) + " s of it (" +
                               fixed(when.first, 3) + " to " + fixed(when.second, 3) + " s)"
                         : std::string()) +
          "; a reading took the host " + fixed(reading_takes_, 3) + " s";
      out_.annotate("missing: " + pose + ": no reading inside its window " + span + idle +
                    (outside_ > 0 ? "; " + late : ""));
    } else {
      if (outside_ > 0)
        out_.annotate("outside: " + pose + ", window " + span + ": " + late + ", not used");
      RtestSample row = p;
      const double n = static_cast<double>(n_);
      const Eigen::Vector3d mean = sum_ / n;
      row.raw = mean;
      Eigen::Vector3d var = Eigen::Vector3d::Zero();
      if (n_ > 1) var = ((sum_sq_ - n * mean.cwiseProduct(mean)) / (n - 1.0)).cwiseMax(0.0);
      row.extra = {std::to_string(n_), fixed(1e3 * std::sqrt(var.maxCoeff()), 3),
                   fixed(t_sum_ / n, 4), fixed(margin_, 4)};
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
      unavailable_.erase(
          std::remove_if(unavailable_.begin(), unavailable_.end(),
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
    std::nth_element(v.begin(), v.begin() + static_cast<long>(count_ / 2),
                     v.begin() + static_cast<long>(count_));
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
  std::optional<std::string> take(ByteTransport& port, RecordSummary& sum, int read_timeout_ms,
                                  double give_up_s) {
    const double t_end = wall_seconds() + give_up_s;
    std::uint8_t buf[256];
    while (next >= lines.size()) {
      const double left = t_end - wall_seconds();
      if (left <= 0) return std::nullopt;
      const std::size_t n =
          port.read(buf, sizeof buf, std::clamp(static_cast<int>(1e3 * left), 1, read_timeout_ms));
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
Poll poll_once(ByteTransport& port, ProbeMode mode, LineReader& lines, RecordSummary& sum,
               const RecordOptions& opt) {
  auto ask = [&](const std::string& request) {
    port.write(request, 200);
    return lines.take(port, sum, opt.read_timeout_ms, opt.silence_timeout_s);
  };
  auto value_of = [&](const GaugeValue& v) -> std::optional<double> {
    if (v.ok()) return v.mm;
    if (v.kind == GaugeValue::Kind::error)
      ++sum.malformed;
    else
      ++sum.over_range;
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

RecordSummary record_rtest(ByteTransport& port, ProbeMode mode, const RtestSession& program,
                           double dwell_s, const Eigen::Matrix3d& probe_dirs,
                           const std::string& path, const RecordOptions& opt) {
  if (program.samples.empty()) throw InvalidArgument("record_rtest: the program has no poses");
  if (!(dwell_s > 0.0)) throw InvalidArgument("record_rtest: dwell_s must be positive");
  RtestSession header = program;
  header.samples.clear();
  header.noise_um.reset();  // what the program was simulated with is not what was measured
  header.extra_columns = {"n", "std_um", "t_s", "margin_s"};
  header.metadata = {
      {"recorded_from", port.path()}, {"recorded_at", utc_now()}, {"probe_mode", to_string(mode)}};
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
    auto pause = [](double s) {
      std::this_thread::sleep_for(std::chrono::duration<double>(std::clamp(s, 0.001, 0.05)));
    };
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
        const double guard =
            poses.has_reading() ? std::max(3.0 * takes, 0.05 * (w.end - w.begin)) : takes;
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
      if (poll.reading && clock)
        poses.add(clock->earliest(sent), clock->latest(received), *poll.reading, true);
      last_ran = wall_seconds();
      pause(0.002);  // between readings inside a window
    }
  });
}

}  // namespace rotacal::hw
