// End to end: virtual instrument -> pty -> recorder -> session file -> identification.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <random>

#include "rotacal/ballbar/identify.hpp"
#include "rotacal/hw/recorder.hpp"
#include "rotacal/hw/virtual_instrument.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/rtest/device.hpp"
#include "rotacal/rtest/identify_joint.hpp"

using namespace rotacal;
using namespace rotacal::hw;

namespace {

std::string temp_file(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("rotacal-test-" + name)).string();
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

BallbarRun run_ballbar(const std::string& name, const FaultInjection& faults, double rate_hz = 100.0,
                       SerialSettings host = {}, std::function<bool(const RecordProgress&)> progress = {}) {
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
  ro.silence_timeout_s = 0.5;
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
  const BallbarRun run = run_ballbar("silence.csv", f);
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
  // The file holds the header and the reason; the reader refuses it for having no rows.
  CHECK_THROWS_WITH(read_ballbar(run.path), Catch::Contains("no data rows"));
  std::ifstream in(run.path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK_THAT(text, Catch::Contains("# summary: 0 rows") && Catch::Contains("wrong baud rate"));
}

TEST_CASE("ballbar: the progress callback stops the recording (Ctrl-C)", "[hw]") {
  const BallbarRun run = run_ballbar("stop.csv", {}, 100.0, {}, [](const RecordProgress& p) { return p.rows < 200; });
  CHECK(run.summary.reason == StopReason::stopped);
  CHECK(run.summary.rows >= 200);
  CHECK(read_ballbar(run.path).samples.size() == run.summary.rows);
}

namespace {
struct RtestRun {
  RecordSummary summary;
  RtestSession recorded;  ///< with dx,dy,dz from the raw readings
  RtestSession program;
  std::vector<Eigen::Vector3d> zeros;
};

RtestTruth rtest_truth() {
  RtestTruth truth;
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

// Polled modes pace on the host clock: `speed` is kept low enough that a pose's window (half
// its dwell) is tens of milliseconds even on a loaded machine or under a sanitizer.
RtestRun run_rtest(ProbeMode mode, double speed) {
  VirtualRtestOptions o;
  o.truth = rtest_truth();
  o.sim.noise_um = 0.3;
  o.sim.seed = 5;
  o.probe_dirs = tripod();
  o.mode = mode;
  o.rate_hz = 50.0;
  o.speed = speed;
  VirtualRtest device(o);
  device.start();
  auto port = open_port(device.port(), {});
  RecordOptions ro;
  ro.rate_hz = o.rate_hz;
  ro.speed = o.speed;
  const std::string path = temp_file("rtest-" + to_string(mode) + ".csv");
  RtestRun run;
  run.summary = record_rtest(*port, mode, device.program(), o.sim.pattern.dwell_s, o.probe_dirs, path, ro);
  device.stop();
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
  const RtestTruth truth = rtest_truth();
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

TEST_CASE("R-test polled modes: every pose is read at rest, to the noise", "[hw]") {
  for (ProbeMode mode : {ProbeMode::keyence, ProbeMode::sylvac}) {
    const RtestRun run = run_rtest(mode, 60.0);
    INFO(to_string(mode) << ": " << run.summary.describe());
    CHECK(run.summary.reason == StopReason::end_of_program);
    CHECK(run.summary.lost == 0);
    REQUIRE(run.recorded.samples.size() == run.program.samples.size());
    // Against the noise-free reading of each pose (simulator, same machine and zeros): the mean
    // of n readings of 0.3 um noise, plus the replies' 0.1 um resolution.
    const RtestTruth truth = rtest_truth();
    const std::vector<std::string> setups = run.program.setups();
    double worst = 0.0;
    for (std::size_t k = 0; k < run.recorded.samples.size(); ++k) {
      const RtestSample& r = run.recorded.samples[k];
      const RtestSample& p = run.program.samples[k];
      CHECK(r.setup == p.setup);
      CHECK(r.rot_deg == p.rot_deg);
      const std::size_t nest = static_cast<std::size_t>(
          std::find(setups.begin(), setups.end(), p.setup) - setups.begin());
      const Eigen::Vector3d exact =
          rtest_reading(truth, run.program.nests.at(p.setup), p.angles_rad(), p.time) + run.zeros[nest];
      worst = std::max(worst, (*r.d - exact).cwiseAbs().maxCoeff());
    }
    CHECK(worst < 1.5e-3);  // 1.5 um: under 5 sigma of one reading, far under a pose-mix-up
  }
}
