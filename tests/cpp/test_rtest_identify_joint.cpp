// SPDX-License-Identifier: BSD-3-Clause
// Tests of rtest/identify_joint.hpp: joint fit, observability per nest arrangement, and the
// gravity/coning map on ../shared/data/rtest_bc_oyama.csv.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <iostream>

#include "../support/synthetic_sessions.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/rtest/identify_joint.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {
using synthetic::oyama_truth;  // rtest_bc_oyama.truth.json
constexpr double kDeg = M_PI / 180.0;

RtestSession load_oyama() {
  return read_rtest(std::string(ROTACAL_SHARED_DIR) + "/data/rtest_bc_oyama.csv");
}

}  // namespace

TEST_CASE("joint map on rtest_bc_oyama.csv shows gravity sag and coning of B (Oyama Sec. 5.3)") {
  const RtestSession s = load_oyama();
  const RtestJointIdentification id = identify_joint(s);
  const MachineModel truth = oyama_truth();
  REQUIRE(id.converged);
  CHECK(id.unobservable.empty());  // default basis, 2 nests at different heights
  // The file's noise is 0.3 um: 504 readings, ~70 unknowns -> sigma within 15%.
  CHECK(id.sigma_um == Approx(0.3).epsilon(0.15));
  const double s_sag = truth.effect_params[0], k_con = truth.effect_params[1];
  std::vector<double> dz, dz_sd;
  for (int i = -3; i <= 3; ++i) {
    const double B = i * 30 * kDeg;
    AxisErrors<double> sd;
    const AxisErrors<double> w = id.model.w_BY(B, &sd);
    INFO("B = " << i * 30 << ": dz_BY " << w[2] * 1e3 << " +- " << sd[2] * 1e3 << " um, alpha_BY "
                << w[3] * 1e6 << " +- " << sd[3] * 1e6 << " urad");
    // Against the truth file, within the reported 1-sigma (3.5 sigma bound; the basis error of
    // 1 - cos B by even powers up to b^6 is < 0.01 um).
    CHECK(std::abs(w[2] - (-s_sag * (1 - std::cos(B)))) <= 3.5 * sd[2] + 1e-9);
    CHECK(std::abs(w[3] - k_con * B) <= 3.5 * sd[3] + 1e-12);
    // The map is the part beyond the location errors: everything else stays near zero.
    for (int k : {0, 1, 4, 5}) CHECK(std::abs(w[k]) <= 4.0 * sd[k] + 1e-12);
    dz.push_back(w[2]);
    dz_sd.push_back(sd[2]);
  }
  // What the paper saw: the table sinks towards B = +-90 deg ...
  CHECK(dz[0] < dz[2] - 3 * (dz_sd[0] + dz_sd[2]));
  CHECK(dz[6] < dz[4] - 3 * (dz_sd[6] + dz_sd[4]));
  CHECK(dz[0] < -0.004);  // 6 um of sag at 90 deg, seen as > 4 um
  // ... and alpha_BY grows linearly with B (coning): slope from the map's two ends.
  AxisErrors<double> sd90;
  const double slope = id.model.w_BY(M_PI / 2, &sd90)[3] / (M_PI / 2);
  CHECK(std::abs(slope - k_con) <= 3.5 * sd90[3] / (M_PI / 2));
  // Location errors against the truth file within their reported uncertainty.
  const auto& names = location_error_names(MachineType::BC_trt);
  for (int j = 0; j < 8; ++j) {
    const ParameterEstimate& p = id.parameter(names[static_cast<std::size_t>(j)]);
    INFO(p.name << " " << p.value << " +- " << p.std << " truth " << truth.errors.v[j]);
    CHECK(p.observable);
    CHECK(std::abs(p.value - truth.errors.v[j]) < 4.0 * p.std);
  }
}

namespace {
using synthetic::oyama_truth;  // rtest_bc_oyama.truth.json
RtestJointIdentification fit_with(const std::vector<Eigen::Vector3d>& nests, bool gamma_cb) {
  RtestSimOptions o;
  o.pattern.nests = nests;
  o.seed = 21;
  RtestJointOptions jo;
  jo.basis.gamma_cb = gamma_cb;
  return identify_joint(simulate_rtest(oyama_truth(), o).session, jo);
}
bool visible(const RtestJointIdentification& id, const std::string& name) {
  return id.parameter(name).observable;
}
}  // namespace

TEST_CASE("which nest arrangements see the C axis' orientation and angular positioning (Fig. 3)") {
  const Eigen::Vector3d n1(100, 0, 60), n2_low(0, -120, 60), n2_high(0, -120, 140),
      n2_above(100, 0, 140), n3(-80, 60, 100);
  // gamma_CB = 0 assumed (Oyama Sec. 4.2):
  {  // one nest: the C axis' tilt cannot be told from its map (needs two points, Fig. 3)
    const auto id = fit_with({n1}, false);
    CHECK_FALSE(visible(id, "E_A0C"));
    CHECK_FALSE(visible(id, "E_B0C"));
    CHECK_FALSE(id.unobservable.empty());
  }
  {  // two nests at the same height: the line joining them has no Z component -> still blind
    const auto id = fit_with({n1, n2_low}, false);
    CHECK_FALSE(visible(id, "E_A0C"));
    CHECK_FALSE(visible(id, "E_B0C"));
  }
  {  // two nests at different heights (the paper's set-up): orientation visible, nothing hidden
    const auto id = fit_with({n1, n2_high}, false);
    CHECK(visible(id, "E_A0C"));
    CHECK(visible(id, "E_B0C"));
    CHECK(id.unobservable.empty());
    CHECK(id.parameter("E_A0C").std < 2e-6);
  }
  // gamma_CB fitted: two nests see 5 of 6 degrees of freedom per pose.
  {
    const auto id = fit_with({n1, n2_above}, true);  // same radius, different heights
    CHECK(visible(id, "E_A0C"));
    CHECK_FALSE(visible(id, "gamma_CB.cos1.b0"));  // first harmonic of angular positioning
    CHECK(visible(id, "gamma_CB.cos2.b0"));
    CHECK(id.unobservable.size() == 2);
  }
  {  // three nests not on one line: everything visible
    const auto id = fit_with({n1, n2_high, n3}, true);
    CHECK(id.unobservable.empty());
    CHECK(visible(id, "gamma_CB.cos1.b0"));
  }
  {  // nests on the C axis: no angular positioning of C at all
    const auto id = fit_with({Eigen::Vector3d(0, 0, 60), Eigen::Vector3d(0, 0, 140)}, true);
    CHECK_FALSE(visible(id, "gamma_CB.cos2.b0"));
    CHECK(visible(id, "E_A0C"));
  }
}

TEST_CASE("joint fit recovers C-axis error motions and reports them in words when hidden") {
  MachineModel t = MachineModel::nominal(MachineType::BC_trt);
  t.effects.effects = {Effect::parse("axial_motion_C_h2"), Effect::parse("radial_motion_C_h2")};
  t.effect_params = {0.002, -0.001, 0.0015, 0.0, 0.0, -0.001};
  RtestSimOptions o;
  o.noise_um = 0.3;
  o.seed = 4;
  const RtestSimulation sim = simulate_rtest(t, o);
  const RtestJointIdentification id = identify_joint(sim.session);
  REQUIRE(id.converged);
  // Axial motion of C in its turning frame is dz_CB = a cos 2C + b sin 2C in the B frame.
  const ParameterEstimate& a = id.parameter("dz_CB.cos2.b0");
  const ParameterEstimate& b = id.parameter("dz_CB.sin2.b0");
  CHECK(std::abs(a.value - 0.002) < 4 * a.std);
  CHECK(std::abs(b.value + 0.001) < 4 * b.std);
  CHECK(id.sigma_um == Approx(0.3).epsilon(0.15));
  CHECK_THROWS_AS(identify_joint(RtestSession{}), InvalidArgument);
}

namespace {
using synthetic::oyama_truth;  // rtest_bc_oyama.truth.json
// W = I / s: white noise of a known sigma s as a noise model.
class KnownWhiteNoise : public ResidualWhitener {
 public:
  KnownWhiteNoise(Eigen::Index n, double s) : n_(n), s_(s) {}
  void apply(Eigen::Ref<Eigen::MatrixXd> c) const override { c /= s_; }
  Eigen::Index size() const override { return n_; }

 private:
  Eigen::Index n_;
  double s_;
};
}  // namespace

TEST_CASE("R-test joint fit with a noise model: same solution, covariance in units of its sigma") {
  RtestSimOptions o;
  o.seed = 77;
  o.noise_um = 0.3;
  const RtestSimulation sim = simulate_rtest(oyama_truth(), o);
  RtestJointOptions as_white;  // no noise model (the basis' misfit of the truth's effects is
  as_white.noise.noise = NoiseHandling::white;  // correlated; here the white fit is the reference)
  const RtestJointIdentification white = identify_joint(sim.session, as_white);
  RtestJointOptions gls;
  const double s = 0.6e-3;  // deliberately twice the true noise: chi2/dof must show it
  gls.whitener = std::make_shared<KnownWhiteNoise>(
      3 * static_cast<Eigen::Index>(sim.session.samples.size()), s);
  const RtestJointIdentification w = identify_joint(sim.session, gls);
  REQUIRE(w.converged);
  CHECK(w.summary.whitened);
  CHECK(w.summary.chi2_per_dof == Approx(0.25).margin(0.05));
  for (std::size_t j = 0; j < w.parameters.size(); ++j) {
    if (!w.parameters[j].observable) continue;
    CHECK(std::abs(w.parameters[j].value - white.parameters[j].value) <=
          1e-3 * white.parameters[j].std);
    // (J^T J)^-1 s^2, not rescaled by the residual variance (white.sigma_um):
    CHECK(w.parameters[j].std ==
          Approx(white.parameters[j].std * s * 1e3 / white.sigma_um).epsilon(1e-3));
  }
}

namespace {
// The 48 poses of `--b-step 60 --c-step 60` (4 B x 6 C x 2 nests) on BC-trt with some poses
// lost, as a recorder starved of CPU loses them; `drop` indexes the session's rows.
RtestSession rtest_b60_c60_without(const std::vector<std::size_t>& drop) {
  MachineModel t = MachineModel::nominal(MachineType::BC_trt);
  t.errors = LocationErrors<double>((Eigen::Matrix<double, 8, 1>() << 0.0612, -0.0767, 2.09e-5,
                                     -2.84e-5, -0.0136, -0.0065, -1.01e-4, -1.16e-5)
                                        .finished());
  RtestSimOptions o;
  o.pattern.b_deg = {-90, -30, 30, 90};
  o.pattern.c_deg = {0, 60, 120, 180, 240, 300};
  o.noise_um = 0.3;
  o.seed = 3;
  RtestSession s = simulate_rtest(t, o).session;
  REQUIRE(s.samples.size() == 48);
  std::vector<RtestSample> kept;
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    if (std::find(drop.begin(), drop.end(), i) == drop.end()) kept.push_back(s.samples[i]);
  s.samples = std::move(kept);
  return s;
}
}  // namespace

TEST_CASE(
    "R-test joint fit with poses lost: a parameter is unobservable or has a positive 1-sigma") {
  // With four B angles the B polynomial to b^6 leaves several null directions of (nearly) equal
  // eigenvalue, whose basis the eigensolver picks at will. Observability was judged per basis
  // vector and one parameter held per vector, the largest share of each: a parameter could be
  // held twice (the free set then singular) or have a small share in each vector, and came out
  // as a value with a 1-sigma of exactly 0 (identify --json: E_X0B 0.00808 +- 0.0).
  const std::vector<std::vector<std::size_t>> drops = {
      {4, 5, 32},
      {9, 18, 24, 41},
      {2, 5, 8, 9, 11, 12, 14, 15, 19, 21, 22, 26, 29, 32, 34, 38, 39, 45, 46, 47},
      {3, 6, 9, 10, 12, 13, 14, 19, 23, 24, 25, 26, 27, 31, 32, 34, 36, 37, 39, 41, 45, 47},
      {3, 4, 5, 6, 7, 11, 14, 16, 17, 18, 19, 21, 23, 25, 27, 28, 30, 32, 34, 38, 39, 40, 42},
  };
  for (const auto& drop : drops) {
    const RtestSession s = rtest_b60_c60_without(drop);
    const RtestJointIdentification id = identify_joint(s);
    INFO(s.samples.size() << " of 48 poses kept");
    CHECK(!id.unobservable.empty());
    for (const ParameterEstimate& p : id.parameters) {
      INFO(p.name << " = " << p.value << " +- " << p.std
                  << (p.observable ? "" : " (unobservable)"));
      if (p.observable) CHECK((std::isfinite(p.std) && p.std > 0.0));
    }
    // Every location error the fit cannot determine is named in a null direction.
    for (const std::string& n : location_error_names(MachineType::BC_trt)) {
      if (id.parameter(n).observable) continue;
      bool named = false;
      for (const std::string& u : id.unobservable) named |= u.find(n + " ") != std::string::npos;
      INFO(n);
      CHECK(named);
    }
  }
}
