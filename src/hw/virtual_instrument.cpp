// SPDX-License-Identifier: BSD-3-Clause
// Virtual instruments: the shared pty/stream/command base, the ballbar and the R-test
// (virtual_instrument.hpp).
#include "rotacal/hw/virtual_instrument.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <random>

#include "rotacal/hw/ballbar_protocol.hpp"
#include "rotacal/hw/transport.hpp"

namespace rotacal::hw {

namespace {
double wall_seconds() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}
}  // namespace

// --------------------------------------------------------------------------- common part

VirtualInstrument::VirtualInstrument(int baud, double speed, double rate_hz,
                                     const FaultInjection& faults)
    : baud_(baud), speed_(speed), faults_(faults), rate_hz_(rate_hz) {
  if (!(speed > 0.0) || !std::isfinite(speed))
    throw InvalidArgument("virtual instrument: speed " + std::to_string(speed) +
                          " must be positive");
  if (!(rate_hz >= 1.0 && rate_hz <= 1000.0))
    throw InvalidArgument("virtual instrument: rate_hz " + std::to_string(rate_hz) +
                          " must be 1..1000");
}

VirtualInstrument::~VirtualInstrument() { halt(); }

void VirtualInstrument::halt() noexcept {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void VirtualInstrument::start() {
  if (thread_.joinable()) return;
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void VirtualInstrument::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (!thread_error_.empty())
    throw SerialError("virtual instrument on " + port() + ": " + thread_error_);
}

VirtualStats VirtualInstrument::stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return stats_;
}

void VirtualInstrument::run() {
  try {
    while (!stop_ && !hung_up_) {
      pollfd p{pty_.master(), POLLIN, 0};
      ::poll(&p, 1, 1);
      serve_once();
    }
  } catch (const std::exception& e) {
    thread_error_ = e.what();
  }
  thread_done_ = true;
  finished_ = true;
}

void VirtualInstrument::mark_finished() {
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    stats_.finished = true;
  }
  finished_at_ = wall_seconds();
  finished_ = true;
}

bool VirtualInstrument::finished() const {
  if (!finished_.load()) return false;
  if (thread_done_.load()) return true;
  return pty_.unread() == 0 || wall_seconds() - finished_at_.load() > 10.0;
}

double VirtualInstrument::now() const {
  return clock_running_ ? (wall_seconds() - clock_origin_) * speed_ : 0.0;
}

void VirtualInstrument::clock_start() {
  clock_origin_ = wall_seconds();
  clock_running_ = true;
}

std::vector<std::string> VirtualInstrument::read_lines() {
  std::vector<std::string> lines;
  if (hung_up_) return lines;
  std::uint8_t buf[512];
  for (;;) {
    const ssize_t n = ::read(pty_.master(), buf, sizeof buf);
    if (n <= 0) break;
    const std::uint8_t* b = buf;
    for (ssize_t i = 0; i < n; ++i) {
      const char c = static_cast<char>(b[i]);
      if (c == '\r' || c == '\n') {
        if (!line_buffer_.empty()) lines.push_back(line_buffer_);
        line_buffer_.clear();
      } else if (line_buffer_.size() < 128) {
        line_buffer_ += c;
      }
    }
  }
  return lines;
}

void VirtualInstrument::write_all(const Bytes& bytes) {
  if (hung_up_ || silent_) return;
  Bytes out = bytes;
  // A host at the wrong baud rate samples the bits at the wrong instants: it reads garbage.
  const int host = pty_.host_baud();
  if (host != 0 && host != baud_)
    for (std::size_t i = 0; i < out.size(); ++i)
      out[i] = static_cast<std::uint8_t>(out[i] * 37u + 11u);
  std::size_t done = 0;
  int stalls = 0;
  while (done < out.size() && !stop_) {
    const ssize_t w = ::write(pty_.master(), out.data() + done, out.size() - done);
    if (w > 0) {
      done += static_cast<std::size_t>(w);
      stalls = 0;
      continue;
    }
    if (w < 0 && errno != EAGAIN && errno != EINTR)
      throw SerialError(std::string("write to the pty master: ") + std::strerror(errno));
    // The host is not reading: wait for room, like a UART with hardware flow control.
    pollfd p{pty_.master(), POLLOUT, 0};
    ::poll(&p, 1, 10);
    if (++stalls > 500) return;  // 5 s without a reader: drop, as a device would
  }
}

void VirtualInstrument::send_reply(const Bytes& bytes) {
  write_all(bytes);
  std::lock_guard<std::mutex> lock(stats_mutex_);
  ++stats_.replies_sent;
}

void VirtualInstrument::send_frame(Bytes frame) {
  const std::uint64_t k = ++stream_count_;  // 1-based frame count
  if (faults_.close_after >= 0 && static_cast<long>(k) > faults_.close_after) {
    // Unplugged after frame close_after: let the host read what was sent first (up to 20 s; it
    // ends as soon as the host has), so that the frames before the unplug arrive however busy
    // the host is: 2 s left 281 of 500 frames unread by a recorder at nice 19 at load 11.
    // FIONREAD counts what the line discipline holds, not what the kernel's flip buffer has yet
    // to hand it (a worker thread does, late on a busy machine): the likeliest reason why the
    // sanitizer build at nice 19, beside a CI run's benchmarks and fuzzers, read 438 of 500 frames
    // (not reproduced on demand). The host has read everything once unread() stays 0 for 200 ms.
    int drained = 0;
    for (int i = 0; i < 2000 && drained < 20 && !stop_; ++i) {
      drained = pty_.unread() == 0 ? drained + 1 : 0;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    pty_.hang_up();
    hung_up_ = true;
    return;
  }
  if (faults_.silence_after >= 0 && static_cast<long>(k) > faults_.silence_after) silent_ = true;
  if (silent_) return;
  const bool drop = faults_.drop_every > 0 && k % faults_.drop_every == 0;
  const bool corrupt = !drop && faults_.corrupt_every > 0 && k % faults_.corrupt_every == 0;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);  // not held while writing: a write may block
    stats_.frames_dropped += drop;
    stats_.frames_corrupted += corrupt;
    stats_.frames_sent += !drop;
  }
  if (drop) return;
  if (corrupt) frame[4 + (k % (frame.size() - 6))] ^= 0x10;  // a payload bit
  if (faults_.split_frames) {
    const std::size_t half = frame.size() / 2;
    write_all(Bytes(frame.begin(), frame.begin() + static_cast<long>(half)));
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    write_all(Bytes(frame.begin() + static_cast<long>(half), frame.end()));
  } else {
    write_all(frame);
  }
  if (faults_.garbage_every > 0 && k % faults_.garbage_every == 0)
    write_all(Bytes{0x13, 0xAA, 0x37, 0x00, 0xFF, 0x55, 0x42});
}

void VirtualInstrument::serve_once() {
  for (const std::string& line : read_lines()) answer(line);
  serve_stream();
}

void VirtualInstrument::answer(const std::string& line) {
  const auto cmd = parse_command(line);
  if (!cmd) return send_reply(encode_text("ERR unknown command '" + line + "'"));
  switch (cmd->command) {
    case StreamCommand::identify:
      send_reply(encode_text("ID " + identity()));
      break;
    case StreamCommand::rate:
      if (streaming_) {
        send_reply(encode_text("ERR RATE while streaming"));
      } else {
        rate_hz_ = cmd->rate_hz;
        send_reply(encode_text("OK RATE " + std::to_string(static_cast<int>(rate_hz_))));
      }
      break;
    case StreamCommand::zero:
      send_reply(encode_text(zero() ? "OK ZERO" : "ERR unknown command '" + line + "'"));
      break;
    case StreamCommand::start:
      streaming_ = true;
      next_sample_ = 0;
      clock_start();
      send_reply(encode_text("OK START"));
      break;
    case StreamCommand::stop:
      streaming_ = false;
      send_reply(encode_text("OK STOP"));
      break;
  }
}

void VirtualInstrument::serve_stream() {
  if (!streaming_) return;
  const double t_now = now();
  for (int batch = 0; streaming_ && !hung_up_ && batch < 200; ++batch) {
    const double t = static_cast<double>(next_sample_) / rate_hz_;
    if (t > t_now) break;
    if (t > stream_end()) {
      streaming_ = false;
      send_reply(encode_text("END"));
      mark_finished();
      break;
    }
    send_frame(sample_frame(t, seq_++));
    ++next_sample_;
  }
}

// --------------------------------------------------------------------------- ballbar

struct VirtualBallbar::Noise {
  std::mt19937_64 rng;
  std::normal_distribution<double> gauss{0.0, 1.0};
};

VirtualBallbar::VirtualBallbar(ProgramTimeline program, const VirtualBallbarOptions& options)
    : VirtualInstrument(options.baud, options.speed, options.rate_hz, options.faults),
      program_(std::move(program)),
      options_(options),
      noise_(std::make_shared<Noise>()) {
  if (!(options.noise_um >= 0.0)) throw InvalidArgument("virtual ballbar: noise_um must be >= 0");
  if (options.truth.machine != program_.header().machine)
    throw InvalidArgument(
        "virtual ballbar: the machine model and the program are for different machines");
  if (static_cast<int>(options.truth.effect_params.size()) != options.truth.effects.num_params())
    throw InvalidArgument("virtual ballbar: the machine model has " +
                          std::to_string(options.truth.effect_params.size()) +
                          " effect parameters, its effects need " +
                          std::to_string(options.truth.effects.num_params()));
  noise_->rng.seed(options.seed);
  // effects.md: the linear-axis polynomials are about the session's mean commanded xyz; the
  // recording samples the program at a steady rate, so its mean is the program's time mean.
  if (!options_.truth.effects.linear_reference) {
    const int n = 4096;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int i = 0; i < n; ++i) sum += program_.at(program_.duration() * (i + 0.5) / n).xyz;
    options_.truth.effects.linear_reference = sum / n;
  }
}

double VirtualBallbar::exact_length(double t) const {
  // The pose the program commands at t, moving as it moves there (backlash, servo lag).
  const BallbarMachineModel& m = options_.truth;
  return predicted_length<double>(m.machine, m.errors, m.pivot, m.effects, m.effect_params.data(),
                                  program_.at(t), program_.motion_at(t));
}

bool VirtualBallbar::zero() {
  // Zero at the current pose (normally done in the calibrator, at L0, before START).
  zero_mm_ = exact_length(now()) - program_.header().ballbar_length;
  return true;
}

namespace {

// The sample frame of a transducer reading `displacement` (mm, from L0 after ZERO) at t.
Bytes ballbar_sample(double t, std::uint16_t seq, double displacement) {
  BallbarFrame f;
  f.seq = seq;
  f.t_us = static_cast<std::uint32_t>(std::llround(t * 1e6));
  const double nm = std::round(displacement * 1e6);
  f.displacement_nm = static_cast<std::int32_t>(std::clamp(nm, -2.0e9, 2.0e9));
  if (std::abs(displacement) > 1.0) f.status |= kStatusOverRange;  // +-1 mm travel
  return encode_ballbar_sample(f);
}

}  // namespace

Bytes VirtualBallbar::sample_frame(double t, std::uint16_t seq) {
  const double L0 = program_.header().ballbar_length;
  const double length = exact_length(t) + 1e-3 * options_.noise_um * noise_->gauss(noise_->rng);
  return ballbar_sample(t, seq, length - L0 - zero_mm_);
}

// --------------------------------------------------------------------------- circular ballbar

namespace {

const CircularSimulationOptions& checked(const CircularSimulationOptions& o) {
  check_circular_simulation(o);
  return o;
}

}  // namespace

// AR(1) noise, one step per streamed reading: e_k = rho e_{k-1} + sqrt(1 - rho^2) sigma z_k,
// started from its stationary distribution.
struct VirtualCircularBallbar::Noise {
  std::mt19937_64 rng;
  std::normal_distribution<double> gauss{0.0, 1.0};
  bool started = false;
  double e = 0.0;  // mm
  double next(double rho, double sigma_mm) {
    const double z = gauss(rng);
    e = started ? rho * e + std::sqrt(1.0 - rho * rho) * sigma_mm * z : sigma_mm * z;
    started = true;
    return e;
  }
};

VirtualCircularBallbar::VirtualCircularBallbar(CircularTimeline program,
                                               const VirtualCircularBallbarOptions& options)
    : VirtualInstrument(options.baud, options.speed, options.rate_hz, options.faults),
      program_(std::move(program)),
      bar_(program_.plan().plan, checked(options.sim)),
      noise_(std::make_shared<Noise>()) {
  noise_->rng.seed(options.sim.seed);
}

bool VirtualCircularBallbar::zero() {
  zero_mm_ = circular_exact_reading(program_, bar_, now()) - program_.header().ballbar_length;
  return true;
}

Bytes VirtualCircularBallbar::sample_frame(double t, std::uint16_t seq) {
  const CircularSimulationOptions& o = bar_.options;
  const double length =
      circular_exact_reading(program_, bar_, t) + noise_->next(o.noise_rho, 1e-3 * o.noise_um);
  return ballbar_sample(t, seq, length - program_.header().ballbar_length - zero_mm_);
}

// --------------------------------------------------------------------------- R-test

struct VirtualRtest::Noise {
  std::mt19937_64 rng;
  std::normal_distribution<double> gauss{0.0, 1.0};
};

VirtualRtest::VirtualRtest(const VirtualRtestOptions& options)
    : VirtualInstrument(options.baud, options.speed, options.rate_hz, options.faults),
      options_(options),
      noise_(std::make_shared<Noise>()) {
  // The simulator's noise-free raw readings are the exact readings of each pose at rest.
  RtestSimOptions exact = options.sim;
  exact.noise_um = 0.0;
  exact.probe_dirs = options.probe_dirs;
  exact.write_d = false;
  RtestSimulation sim = simulate_rtest(options.truth, exact);
  program_ = std::move(sim.session);
  zeros_ = std::move(sim.probe_zeros);
  for (RtestSample& s : program_.samples) {
    exact_.push_back(*s.raw);
    s.raw.reset();
  }
  program_.probe_dirs.clear();
  program_.noise_um.reset();
  noise_->rng.seed(options.sim.seed + 7919);
}

Eigen::Vector3d VirtualRtest::readings_at(double t, bool* at_rest) {
  const auto& rows = program_.samples;
  const double dwell = options_.sim.pattern.dwell_s;
  const long last = static_cast<long>(rows.size()) - 1;
  const long k = std::clamp(std::lround((t - rows.front().time) / dwell), 0L, last);
  const PoseWindow w = pose_window(rows[static_cast<std::size_t>(k)].time, dwell);
  Eigen::Vector3d r;
  if (w.contains(t, t) || (k == 0 && t < w.begin) || (k == last && t > w.end)) {
    *at_rest = true;
    r = exact_[static_cast<std::size_t>(k)];
  } else {
    // Moving between poses: the readings slide from one pose's to the next, with a
    // following-error bump that a recorder must not mistake for a measurement.
    *at_rest = false;
    const auto a = static_cast<std::size_t>(t > w.end ? k : k - 1);
    const double from = pose_window(rows[a].time, dwell).end,
                 to = pose_window(rows[a + 1].time, dwell).begin;
    const double u = (t - from) / (to - from);
    r = exact_[a] + u * (exact_[a + 1] - exact_[a]) +
        Eigen::Vector3d::Constant(0.005 * std::sin(M_PI * u));
  }
  for (int i = 0; i < 3; ++i) r[i] += 1e-3 * options_.sim.noise_um * noise_->gauss(noise_->rng);
  return r;
}

double VirtualRtest::stream_end() const {
  return program_.samples.back().time +
         0.5 * options_.sim.pattern.dwell_s;  // the last dwell is over
}

void VirtualRtest::serve_once() {
  VirtualInstrument::serve_once();
  // Polled: the pattern has run once its last dwell is over, asked or not.
  if (options_.mode != ProbeMode::stream && clock_running() && now() > stream_end())
    mark_finished();
}

void VirtualRtest::answer(const std::string& line) {
  if (options_.mode == ProbeMode::stream) return VirtualInstrument::answer(line);
  if (!clock_running()) clock_start();  // polled: the program starts at the first request
  auto value = [](double mm) {
    if (mm > 2.0) return GaugeValue{GaugeValue::Kind::over_range, 0.0, 1};
    if (mm < -2.0) return GaugeValue{GaugeValue::Kind::under_range, 0.0, 1};
    return GaugeValue{GaugeValue::Kind::value, mm, 0};
  };
  bool rest = false;
  const Eigen::Vector3d r = readings_at(now(), &rest);
  if (options_.mode == ProbeMode::sylvac) {
    const auto ch = parse_sylvac_request(line);
    send_reply(ch ? format_sylvac_reply(value(r[*ch - 1]))
                  : format_sylvac_reply(GaugeValue{GaugeValue::Kind::error, 0.0, -1}));
    return;
  }
  const auto ch = parse_keyence_request(line);
  KeyenceReply reply;
  if (!ch) {
    reply = {0, {GaugeValue{GaugeValue::Kind::error, 0.0, 2}}};  // ER,M0,02: command error
  } else if (*ch == 0) {
    reply = {0, {value(r[0]), value(r[1]), value(r[2])}};
  } else {
    reply = {*ch, {value(r[*ch - 1])}};
  }
  send_reply(format_keyence_reply(reply));
}

Bytes VirtualRtest::sample_frame(double t, std::uint16_t seq) {
  bool rest = false;
  const Eigen::Vector3d r = readings_at(t, &rest);
  ProbeFrame f;
  f.seq = seq;
  f.t_us = static_cast<std::uint32_t>(std::llround(t * 1e6));
  for (int i = 0; i < 3; ++i) {
    f.nm[i] = static_cast<std::int32_t>(std::llround(std::clamp(r[i], -2.0, 2.0) * 1e6));
    if (std::abs(r[i]) > 2.0) f.status |= static_cast<std::uint8_t>(1u << i);
  }
  return encode_probe_sample(f);
}

}  // namespace rotacal::hw
