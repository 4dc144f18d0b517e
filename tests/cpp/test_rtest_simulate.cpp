// SPDX-License-Identifier: BSD-3-Clause
// Tests of rtest/simulate.hpp, cross-checked against the independent implementation's session
// ../shared/data/rtest_bc_oyama.csv.
#include <catch2/catch.hpp>

#include "../support/synthetic_sessions.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {
using synthetic::oyama_truth;  // rtest_bc_oyama.truth.json
std::vector<RtestSample> load_rows(const std::string& path) { return read_rtest(path).samples; }

}  // namespace

TEST_CASE("simulated pattern and readings match the independent implementation's file") {
  const auto rows = load_rows(std::string(ROTACAL_SHARED_DIR) + "/data/rtest_bc_oyama.csv");
  RtestSimOptions o;
  o.noise_um = 0.0;
  o.probe_zero_um = 0.0;
  const RtestSimulation sim = simulate_rtest(oyama_truth(), o);
  REQUIRE(sim.session.samples.size() == rows.size());  // 2 x 84
  // Residual file - simulation after one constant offset per set-up: the file's noise (0.3 um).
  for (const std::string setup : {"1", "2"}) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    std::vector<Eigen::Vector3d> diff;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (rows[i].setup != setup) continue;
      const RtestSample& s = sim.session.samples[i];
      CHECK(s.setup == setup);
      CHECK(s.tilt_deg == rows[i].tilt_deg);
      CHECK(s.rot_deg == rows[i].rot_deg);
      CHECK((s.xyz - rows[i].xyz).norm() < 2e-6);  // file has 6 decimals
      diff.push_back(*rows[i].d - *s.d);
      mean += diff.back();
    }
    mean /= static_cast<double>(diff.size());
    double ss = 0.0;
    for (const auto& d : diff) ss += (d - mean).squaredNorm();
    const double rms_um = std::sqrt(ss / (3.0 * diff.size())) * 1e3;
    INFO("set-up " << setup << " rms " << rms_um << " um");
    // 252 values: the RMS of N(0, 0.3 um) lies within 0.3 +- 15% at > 3 sigma.
    CHECK(rms_um > 0.25);
    CHECK(rms_um < 0.35);
  }
}

TEST_CASE("noise and probe zeros have the requested statistics") {
  RtestSimOptions o;
  o.noise_um = 0.5;
  o.probe_zero_um = 30.0;
  o.seed = 11;
  const MachineModel truth = oyama_truth();
  const RtestSimulation sim = simulate_rtest(truth, o);
  REQUIRE(sim.probe_zeros.size() == 2);
  double ss = 0.0;
  for (const RtestSample& s : sim.session.samples) {
    const std::size_t n = s.setup == "1" ? 0 : 1;
    const Eigen::Vector3d clean =
        rtest_reading(truth, sim.session.nests.at(s.setup), s.angles_rad(), s.time);
    ss += (*s.d - clean - sim.probe_zeros[n]).squaredNorm();
  }
  const double sigma_um = std::sqrt(ss / (3.0 * sim.session.samples.size())) * 1e3;
  CHECK(sigma_um == Approx(0.5).epsilon(0.1));  // 504 values: 10% is > 3 sigma
  CHECK(sim.session.noise_um.value() == 0.5);
  CHECK(sim.session.nests.size() == 2);
}

TEST_CASE("raw probe readings with probe directions") {
  RtestSimOptions o;
  Eigen::Matrix3d D;
  D << 0.8, 0.0, -0.6, -0.4, 0.69, -0.6, -0.4, -0.69, -0.6;
  for (int k = 0; k < 3; ++k) D.row(k).normalize();
  o.probe_dirs = D;
  o.write_d = false;
  const RtestSimulation sim = simulate_rtest(oyama_truth(), o);
  CHECK(sim.session.probe_dirs.size() == 3);
  for (const RtestSample& s : sim.session.samples) {
    CHECK(s.raw.has_value());
    CHECK_FALSE(s.d.has_value());
  }
  o.write_d = true;
  const RtestSimulation both = simulate_rtest(oyama_truth(), o);
  const RtestSample& s = both.session.samples[5];
  CHECK((D * *s.d - *s.raw).norm() < 1e-14);
}

TEST_CASE("bad simulator input is refused") {
  RtestSimOptions o;
  o.pattern.nests.clear();
  CHECK_THROWS_AS(simulate_rtest(oyama_truth(), o), InvalidArgument);
  MachineModel t = oyama_truth();
  t.effect_params.pop_back();
  CHECK_THROWS_AS(simulate_rtest(t, RtestSimOptions{}), InvalidArgument);
}
