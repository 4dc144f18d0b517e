// SPDX-License-Identifier: BSD-3-Clause
// End to end: virtual instrument -> pty -> recorder -> session file -> identification.
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/hw/recorder.hpp"
#include "rotacal/hw/virtual_instrument.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/rtest/device.hpp"
#include "rotacal/rtest/identify_joint.hpp"

using namespace rotacal;
using namespace rotacal::hw;

namespace {

// Unique per process: other test runs on the same machine write their own recordings.
std::string temp_file(const std::string& name) {
  static const std::filesystem::path dir = [] {
    auto d =
        std::filesystem::temp_directory_path() / ("rotacal-test-hw-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return (dir / name).string();
}

BallbarPlan small_plan() {
  BallbarSetup setup;  // the seven tests at 2 deg steps: about 40 s of program
  setup.step_deg = 2.0;
  return plan_ballbar_test(setup);
}

BallbarMachineModel machine_with_errors(const BallbarPlan& plan) {
  BallbarMachineModel t;
  t.machine = plan.setup.machine;
  t.errors.v << 0.03, -0.02, 4e-5, -6e-5, 0.025, 0.04, 3e-5, -5e-5;
  t.pivot = plan.setup.pivot + Eigen::Vector3d(0.012, -0.008, 0.015);
  return t;
}

struct BallbarRun {
  RecordSummary summary;
  VirtualStats device;
  std::string path;
};

// `silence_s`: long enough that a host starved of CPU for seconds (both cores busy, nice 19)
// does not take its own stall for a silent instrument.
BallbarRun run_ballbar(const std::string& name, const FaultInjection& faults,
                       double rate_hz = 100.0, SerialSettings host = {},
                       std::function<bool(const RecordProgress&)> progress = {},
                       double silence_s = 10.0) {
  const BallbarPlan plan = small_plan();
  VirtualBallbarOptions o;
  o.truth = machine_with_errors(plan);
  o.noise_um = 0.5;
  o.seed = 3;
  o.speed = 40.0;
  o.faults = faults;
  VirtualBallbar device(ProgramTimeline(plan), o);
  device.start();
  auto port = open_port(device.port(), host);
  RecordOptions ro;
  ro.rate_hz = rate_hz;
  ro.silence_timeout_s = silence_s;
  ro.progress = std::move(progress);
  ro.progress_interval_s = 0.0;
  BallbarRun run{{}, {}, temp_file(name)};
  run.summary = record_ballbar(*port, ProgramTimeline(plan), run.path, ro);
  device.stop();
  run.device = device.stats();
  return run;
}

}  // namespace

TEST_CASE("ballbar: a clean recording identifies the simulated machine within 3 sigma", "[hw]") {
  const BallbarRun run = run_ballbar("clean.csv", {});
  INFO(run.summary.describe());
  CHECK(run.summary.reason == StopReason::end_of_program);
  CHECK(run.summary.lost == 0);
  CHECK(run.summary.crc_errors == 0);
  CHECK(run.summary.rows == run.device.frames_sent);
  const BallbarSession s = read_ballbar(run.path);
  CHECK(s.samples.size() == run.summary.rows);
  CHECK(s.samples.size() > 3000);  // 100 Hz over the program
  const BallbarIdentification id = identify_joint(s);
  REQUIRE(id.converged);
  const BallbarMachineModel truth = machine_with_errors(small_plan());
  CHECK(id.residual_rms_um == Approx(0.5).epsilon(0.1));
  for (int j = 0; j < 8; ++j) {
    const ParameterEstimate& p = id.parameters[static_cast<std::size_t>(j)];
    INFO(p.name << " = " << p.value << " +- " << p.std << ", truth " << truth.errors.v[j]);
    CHECK(std::abs(p.value - truth.errors.v[j]) <= 3.0 * p.std);
  }
}

TEST_CASE("ballbar: garbage, corrupt, dropped and split frames are counted and marked", "[hw]") {
  FaultInjection f;
  f.garbage_every = 50;
  f.corrupt_every = 97;
  f.drop_every = 113;
  f.split_frames = true;
  const BallbarRun run = run_ballbar("faults.csv", f, 50.0);
  INFO(run.summary.describe());
  CHECK(run.summary.reason == StopReason::end_of_program);
  CHECK(run.summary.crc_errors == run.device.frames_corrupted);
  // a corrupt frame is dropped by the decoder, so its sequence number is missing too
  CHECK(run.summary.lost == run.device.frames_dropped + run.device.frames_corrupted);
  CHECK(run.summary.rows == run.device.frames_sent - run.device.frames_corrupted);
  CHECK(run.summary.garbage_bytes >= 7 * (run.device.frames_sent / 50));
  const BallbarSession s = read_ballbar(run.path);
  CHECK(s.samples.size() == run.summary.rows);
  std::size_t gaps = 0, corrupt = 0;
  for (const Annotation& a : s.annotations) {
    gaps += a.text.rfind("gap:", 0) == 0;
    corrupt += a.text.rfind("corrupt:", 0) == 0;
  }
  CHECK(gaps >= run.device.frames_dropped);
  CHECK(corrupt >= 1);
}

TEST_CASE("ballbar: unplugged mid-stream, the file keeps every row read", "[hw]") {
  FaultInjection f;
  f.close_after = 500;
  const BallbarRun run = run_ballbar("unplug.csv", f);
  INFO(run.summary.describe());
  CHECK(run.summary.reason == StopReason::disconnected);
  // Bytes in flight when the line dies are gone (as with a real unplug); what was read is kept.
  CHECK(run.summary.rows == run.summary.frames);
  CHECK(run.summary.rows >= 450);
  CHECK(run.summary.rows <= 500);
  CHECK(read_ballbar(run.path).samples.size() == run.summary.rows);
}

TEST_CASE("ballbar: silence stops the recorder cleanly", "[hw]") {
  FaultInjection f;
  f.silence_after = 300;
  const BallbarRun run = run_ballbar("silence.csv", f, 100.0, {}, {}, 3.0);
  INFO(run.summary.describe());
  CHECK(run.summary.reason == StopReason::silence);
  CHECK(run.summary.rows == 300);
  CHECK(read_ballbar(run.path).samples.size() == 300);
}

TEST_CASE("ballbar: a host at the wrong baud rate gets no valid data and says so", "[hw]") {
  SerialSettings host;
  host.baud = 9600;  // the instrument talks at 115200
  const BallbarRun run = run_ballbar("baud.csv", {}, 100.0, host);
  INFO(run.summary.describe());
  CHECK(run.summary.reason == StopReason::no_valid_data);
  CHECK_THAT(run.summary.detail, Catch::Contains("baud"));
  CHECK(run.summary.rows == 0);
  // Nothing measured, nothing written: the reason is in the summary.
  CHECK_FALSE(std::filesystem::exists(run.path));
}

TEST_CASE("ballbar: a recording with no row leaves the previous file as it was", "[hw]") {
  // Issue 32: an instrument that never answers replaced a 1,804-row session with an empty file.
  const std::string path = temp_file("previous.csv");
  {
    std::ofstream(path) << "the previous session\n";
  }
  SerialSettings host;
  host.baud = 9600;
  const BallbarRun run = run_ballbar("previous.csv", {}, 100.0, host, {}, 1.0);
  CHECK(run.summary.rows == 0);
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(text == "the previous session\n");
  for (const auto& e :
       std::filesystem::directory_iterator(std::filesystem::path(path).parent_path()))
    CHECK(e.path().extension() != ".part");
}

TEST_CASE("ballbar: the progress callback stops the recording (Ctrl-C)", "[hw]") {
  const BallbarRun run =
      run_ballbar("stop.csv", {}, 100.0, {}, [](const RecordProgress& p) { return p.rows < 200; });
  CHECK(run.summary.reason == StopReason::stopped);
  CHECK(run.summary.rows >= 200);
  CHECK(read_ballbar(run.path).samples.size() == run.summary.rows);
}

namespace {
struct RtestRun {
  RecordSummary summary;
  std::string path;
  RtestSession recorded;  ///< with dx,dy,dz from the raw readings
  RtestSession program;
  std::vector<Eigen::Vector3d> zeros;
};

MachineModel rtest_truth() {
  MachineModel truth;
  truth.machine = MachineType::BC_trt;
  truth.errors.v << 0.02, -0.015, 3e-5, -4e-5, 0.01, 0.012, 2e-5, -3e-5;
  return truth;
}

Eigen::Matrix3d tripod() {
  Eigen::Matrix3d dirs;
  dirs.row(0) = Eigen::Vector3d(1, 0, -1).normalized();
  dirs.row(1) = Eigen::Vector3d(0, 1, -1).normalized();
  dirs.row(2) = Eigen::Vector3d(-1, -1, -1).normalized();
  return dirs;
}

// A host that stalls once, for `stall_s` after its `after`-th read that brought data, as a
// host does when another process holds the CPU: the reply is in, the host is not.
class LateHost final : public ByteTransport {
 public:
  LateHost(std::unique_ptr<ByteTransport> port, int after, double stall_s)
      : port_(std::move(port)), after_(after), stall_s_(stall_s) {}
  std::size_t read(std::uint8_t* buf, std::size_t max, int timeout_ms) override {
    const std::size_t n = port_->read(buf, max, timeout_ms);
    if (n > 0 && ++reads_ == after_)
      std::this_thread::sleep_for(std::chrono::duration<double>(stall_s_));
    return n;
  }
  void write(const std::uint8_t* data, std::size_t n, int timeout_ms) override {
    port_->write(data, n, timeout_ms);
  }
  void flush_input() override { port_->flush_input(); }
  void close() override { port_->close(); }
  const std::string& path() const override { return port_->path(); }

 private:
  std::unique_ptr<ByteTransport> port_;
  int after_;
  double stall_s_;
  int reads_ = 0;
};

// Polled modes pace on the host clock: `speed` is kept low enough that a pose's read window
// (80 % of its dwell) is most of a second of real time, so that a host starved of CPU (a
// loaded machine, nice 19, a sanitizer) still reads every pose inside its window.
// `host_stall_s` > 0: the host stalls that long once, early in the program (LateHost).
RtestRun run_rtest(ProbeMode mode, double speed, const RtestPattern& pattern = {},
                   double host_stall_s = 0.0) {
  VirtualRtestOptions o;
  o.truth = rtest_truth();
  o.sim.pattern = pattern;
  o.sim.noise_um = 0.3;
  o.sim.seed = 5;
  o.probe_dirs = tripod();
  o.mode = mode;
  o.rate_hz = 50.0;
  o.speed = speed;
  VirtualRtest device(o);
  device.start();
  std::unique_ptr<ByteTransport> port = open_port(device.port(), {});
  if (host_stall_s > 0) port = std::make_unique<LateHost>(std::move(port), 10, host_stall_s);
  RecordOptions ro;
  ro.rate_hz = o.rate_hz;
  ro.speed = o.speed;
  ro.silence_timeout_s = 10.0;  // a starved host's stall is not a silent instrument
  const std::string path =
      temp_file("rtest-" + to_string(mode) + (host_stall_s > 0 ? "-late" : "") + ".csv");
  RtestRun run;
  run.summary =
      record_rtest(*port, mode, device.program(), o.sim.pattern.dwell_s, o.probe_dirs, path, ro);
  device.stop();
  run.path = path;
  run.recorded = displacements_from_raw(read_rtest(path));
  run.program = device.program();
  run.zeros = device.probe_zeros();
  return run;
}
}  // namespace

TEST_CASE("R-test stream: the recorded pattern identifies the machine within 3 sigma", "[hw]") {
  const RtestRun run = run_rtest(ProbeMode::stream, 150.0);
  INFO(run.summary.describe());
  CHECK(run.summary.reason == StopReason::end_of_program);
  CHECK(run.summary.lost == 0);
  REQUIRE(run.recorded.samples.size() == run.program.samples.size());
  const RtestJointIdentification id = identify_joint(run.recorded);
  REQUIRE(id.converged);
  const MachineModel truth = rtest_truth();
  int checked = 0;
  for (int j = 0; j < 8; ++j) {
    const ParameterEstimate& p = id.parameters[static_cast<std::size_t>(j)];
    if (!p.observable) continue;
    INFO(p.name << " = " << p.value << " +- " << p.std << ", truth " << truth.errors.v[j]);
    CHECK(std::abs(p.value - truth.errors.v[j]) <= 3.0 * p.std);
    ++checked;
  }
  CHECK(checked >= 4);
}

namespace {
// The largest deviation, mm, of a recorded pose from the noise-free reading of the pose it is
// labelled with (simulator, same machine and zeros); every row must be a commanded pose.
double worst_deviation(const RtestRun& run) {
  const MachineModel truth = rtest_truth();
  const std::vector<std::string> setups = run.program.setups();
  double worst = 0.0;
  for (const RtestSample& r : run.recorded.samples) {
    const auto p = std::find_if(
        run.program.samples.begin(), run.program.samples.end(), [&](const RtestSample& q) {
          return q.setup == r.setup && q.tilt_deg == r.tilt_deg && q.rot_deg == r.rot_deg;
        });
    REQUIRE(p != run.program.samples.end());
    const std::size_t nest = static_cast<std::size_t>(
        std::find(setups.begin(), setups.end(), p->setup) - setups.begin());
    const Eigen::Vector3d exact =
        rtest_reading(truth, run.program.nests.at(p->setup), p->angles_rad(), p->time) +
        run.zeros[nest];
    worst = std::max(worst, (*r.d - exact).cwiseAbs().maxCoeff());
  }
  return worst;
}

// Every row says when it was read and how far inside its pose's window: n >= 1 readings, the
// mean time t_s within the window around the pose's time, margin_s >= 0.
void check_read_times(const RtestRun& run, double dwell_s) {
  const auto& cols = run.recorded.extra_columns;
  REQUIRE(cols == std::vector<std::string>{"n", "std_um", "t_s", "margin_s"});
  for (const RtestSample& r : run.recorded.samples) {
    INFO("pose at t=" << r.time << ": n=" << r.extra[0] << " t_s=" << r.extra[2]
                      << " margin_s=" << r.extra[3]);
    const PoseWindow w = pose_window(r.time, dwell_s);
    CHECK(std::stoi(r.extra[0]) >= 1);
    CHECK(w.contains(std::stod(r.extra[2]), std::stod(r.extra[2])));
    CHECK(std::stod(r.extra[3]) >= 0.0);
  }
}

std::size_t count_lines(const std::string& path, const std::string& prefix) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) n += line.rfind(prefix, 0) == 0;
  return n;
}

// 24 poses (two nests, B every 90 deg, C every 90 deg): enough to see every kind of move.
RtestPattern polled_pattern() {
  RtestPattern p;
  p.b_deg = {-90, 0, 90};
  p.c_deg = {0, 90, 180, 270};
  return p;
}

// The `# missing:` lines of a recording that show the host was late for that pose: it could
// not read (did not run, or waited for a reply) for a quarter of the window or more, or one
// reading took it that long. A pose lost for any other reason (a recorder reading at the
// wrong time) does not say so.
std::size_t losses_to_a_late_host(const std::string& path, double window_s) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("# missing: pose", 0) != 0) continue;
    auto seconds_after = [&](const std::string& said) {
      const auto at = line.find(said);
      return at == std::string::npos ? 0.0 : std::stod(line.substr(at + said.size()));
    };
    n += std::max(seconds_after("the host could not read for "),
                  seconds_after("a reading took the host ")) >= 0.25 * window_s;
  }
  return n;
}
}  // namespace

TEST_CASE("R-test polled modes: every pose is read inside its window, to the noise", "[hw]") {
  // Speed 6: a 1 s dwell and a 0.8 s read window of real time per pose. A pose may be lost only
  // when the host really was late for it (a stall of a quarter of its window or more, as on a
  // machine where other processes hold both cores), and then it is counted and marked.
  for (ProbeMode mode : {ProbeMode::keyence, ProbeMode::sylvac}) {
    const RtestPattern pattern = polled_pattern();
    const RtestRun run = run_rtest(mode, 6.0, pattern);
    INFO(to_string(mode) << ": " << run.summary.describe());
    CHECK(run.summary.reason == StopReason::end_of_program);
    CHECK(run.recorded.samples.size() + run.summary.lost == run.program.samples.size());
    CHECK(count_lines(run.path, "# missing: pose") == run.summary.lost);
    CHECK(losses_to_a_late_host(run.path, kRtestRestFraction * pattern.dwell_s) ==
          run.summary.lost);
    CHECK(run.recorded.samples.size() >= run.program.samples.size() / 2);
    // Rows in program order, each at its commanded pose.
    std::size_t k = 0;
    for (const RtestSample& r : run.recorded.samples) {
      while (k < run.program.samples.size() && run.program.samples[k].time != r.time) ++k;
      REQUIRE(k < run.program.samples.size());
      CHECK(r.setup == run.program.samples[k].setup);
      CHECK(r.rot_deg == run.program.samples[k].rot_deg);
    }
    check_read_times(run, pattern.dwell_s);
    // The mean of n readings of 0.3 um noise, plus the replies' 0.1 um resolution.
    CHECK(worst_deviation(run) <
          1.5e-3);  // 1.5 um: under 5 sigma of one reading, far under a pose mix-up
  }
}

TEST_CASE("R-test polled: a host that stalls past a window loses that pose, counted and marked",
          "[hw]") {
  RtestPattern pattern = polled_pattern();
  pattern.nests.resize(1);  // 12 poses
  // The host stalls 2.5 s (15 s of program) at its 10th read: the reading it was taking is not
  // surely inside its pose's window, and at least one whole window (4.8 s, one every 6 s)
  // passes unread, wherever in the program the stall falls.
  const RtestRun run = run_rtest(ProbeMode::keyence, 6.0, pattern, 2.5);
  INFO(run.summary.describe());
  CHECK(run.summary.reason == StopReason::end_of_program);
  CHECK(run.summary.lost >= 1);
  CHECK(run.summary.outside_window >= 1);
  // Never silent: every pose is a row or a `# missing:` line, and the count says so.
  CHECK(count_lines(run.path, "# missing: pose") == run.summary.lost);
  CHECK(losses_to_a_late_host(run.path, kRtestRestFraction * pattern.dwell_s) == run.summary.lost);
  CHECK(run.recorded.samples.size() + run.summary.lost == run.program.samples.size());
  std::ifstream in(run.path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK_THAT(text, Catch::Contains("not surely inside it"));
  // What was kept was read at rest, at the pose it is labelled with.
  check_read_times(run, pattern.dwell_s);
  CHECK(worst_deviation(run) < 1.5e-3);
}
