#include <catch2/catch.hpp>

#include <Eigen/SVD>
#include <random>

#include "rotacal/core/least_squares.hpp"

#include "rotacal/diagnose/rtest_diagnosis.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/rtest/simulate.hpp"

using namespace rotacal;

namespace {
RtestTruth random_table(std::mt19937& rng) {
  std::normal_distribution<double> N(0.0, 1.0);
  RtestTruth t;
  t.machine = MachineType::BC_trt;
  for (int i = 0; i < 8; ++i) t.errors.v[i] = location_error_is_angle(i) ? 3e-5 * N(rng) : 0.02 * N(rng);
  return t;
}
}  // namespace

TEST_CASE("R-test diagnosis finds the effects hidden in the independent implementation's file", "[diagnose]") {
  // rtest_bc_oyama.truth.json: gravity_sag_B = 0.006 mm, coning_B = 1.45e-4 rad/rad, noise 0.3 um.
  RtestSession s = read_rtest(std::string(ROTACAL_SHARED_DIR) + "/data/rtest_bc_oyama.csv");
  const Diagnosis D = diagnose_rtest(s);  // the file declares no noise: it is estimated
  CHECK(D.baseline.chi2_per_dof > 50.0);
  REQUIRE(D.findings.size() == 2);
  std::vector<std::string> ids = {D.findings[0].effect.id(), D.findings[1].effect.id()};
  CHECK(std::find(ids.begin(), ids.end(), "gravity_sag_B") != ids.end());
  CHECK(std::find(ids.begin(), ids.end(), "coning_B") != ids.end());
  for (const Finding& F : D.findings) {
    REQUIRE(F.parameters.size() == 1);
    const double truth = F.effect.id() == "gravity_sag_B" ? 0.006 : 1.45e-4;
    INFO(F.effect.id() << " = " << F.parameters[0].value << " +- " << F.parameters[0].std);
    CHECK(std::abs(F.parameters[0].value - truth) <= 3 * F.parameters[0].std);
    CHECK(F.gain.cv_rms_after_um < F.gain.cv_rms_before_um);
  }
  CHECK(D.final_fit.residuals.size() == 3 * 168);
  CHECK(D.baseline.noise_um == Approx(0.3).epsilon(0.1));  // 0.3 um in the truth file
  CHECK_FALSE(D.unexplained.present);
}

TEST_CASE("R-test diagnosis: null data gives no finding; a hidden runout is found", "[diagnose]") {
  std::mt19937 rng(21);
  for (unsigned seed : {1u, 2u}) {
    RtestSimOptions o;
    o.seed = seed;
    RtestSession s = simulate_rtest(random_table(rng), o).session;
    s.noise_um = o.noise_um;
    const Diagnosis D = diagnose_rtest(s);
    CHECK(D.findings.empty());
    CHECK_FALSE(D.unexplained.present);
  }
  RtestTruth t = random_table(rng);
  t.effects.effects = {Effect::parse("radial_motion_C_h2")};
  t.effect_params = {2e-3, 0.0, 0.0, 1e-3};  // a 2-lobe bearing track, 1-2 um
  RtestSimOptions o;
  o.seed = 9;
  RtestSession s = simulate_rtest(t, o).session;
  s.noise_um = o.noise_um;
  const Diagnosis D = diagnose_rtest(s);
  REQUIRE_FALSE(D.findings.empty());
  CHECK(D.findings[0].effect.id() == "radial_motion_C_h2");
  for (std::size_t k = 0; k < 4; ++k) {
    const ParameterEstimate& p = D.findings[0].parameters[k];
    if (p.observable) CHECK(std::abs(p.value - t.effect_params[k]) <= 3 * p.std);
  }
  // The R-test cannot see its own instrument's ballbar entries: they are no candidates.
  for (const auto& round : D.rounds)
    for (const CandidateScore& c : round) CHECK(c.effect.rfind("ballbar_", 0) != 0);
}

TEST_CASE("every catalogue effect an R-test can see, hidden at 5 sigma, is found first", "[diagnose]") {
  // Same rule as the ballbar test: the amplitude gives 5 sigma RMS of what the location errors
  // and probe zeros cannot absorb, if a plausible size of the effect can do that.
  std::mt19937 rng(31);
  const double noise_um = 0.3;
  int tried = 0;
  std::string invisible;
  RtestDiagnosisProblem probe([&] {
    RtestSimOptions o;
    RtestSession s = simulate_rtest(random_table(rng), o).session;
    s.noise_um = noise_um;
    return s;
  }());
  for (const Effect& effect : probe.candidates(2)) {
    RtestTruth t = random_table(rng);
    RtestSimOptions o;
    o.noise_um = 0.0;
    RtestSession clean = simulate_rtest(t, o).session;
    clean.noise_um = noise_um;
    RtestDiagnosisProblem P(clean);
    const ModelFit at = P.fit(EffectModel{});
    Eigen::VectorXd m(effect.num_params());
    for (int j = 0; j < m.size(); ++j) m[j] = plausible_magnitude(effect.param_units()[static_cast<std::size_t>(j)]);
    const Eigen::MatrixXd Jc = P.candidate_jacobian(at, effect) * m.asDiagonal();
    const Eigen::MatrixXd perp = Jc - at.jacobian * at.jacobian.completeOrthogonalDecomposition().solve(Jc);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(perp, Eigen::ComputeThinV);
    const double per_size = svd.singularValues()[0] / std::sqrt(static_cast<double>(perp.rows()));
    const double sizes = 5.0 * noise_um * 1e-3 / per_size;
    if (!(per_size > 0) || sizes * svd.matrixV().col(0).cwiseAbs().maxCoeff() > 1.0) {
      invisible += effect.id() + " ";
      continue;
    }
    const Eigen::VectorXd p = m.cwiseProduct(svd.matrixV().col(0)) * sizes;
    t.effects.effects = {effect};
    t.effect_params.assign(p.data(), p.data() + p.size());
    RtestSimOptions noisy;
    noisy.noise_um = noise_um;
    noisy.seed = 100u + static_cast<unsigned>(tried);
    RtestSession s = simulate_rtest(t, noisy).session;
    s.noise_um = noise_um;
    const Diagnosis D = diagnose_rtest(s);
    ++tried;
    INFO(effect.id() << ": first finding " << (D.findings.empty() ? "none" : D.findings[0].effect.id()));
    REQUIRE_FALSE(D.findings.empty());
    bool named = D.findings[0].effect == effect;
    for (const Ambiguity& a : D.ambiguous)
      named = named || (a.effects[0] == D.findings[0].effect.id() &&
                        std::find(a.effects.begin(), a.effects.end(), effect.id()) != a.effects.end());
    CHECK(named);
    if (D.findings[0].effect == effect)
      for (Eigen::Index k = 0; k < p.size(); ++k) {
        const ParameterEstimate& e = D.findings[0].parameters[static_cast<std::size_t>(k)];
        if (e.observable) CHECK(std::abs(e.value - p[k]) <= 3.0 * e.std + 1e-12);
      }
    CHECK(D.findings[0].gain.cv_rms_after_um < D.findings[0].gain.cv_rms_before_um);
  }
  WARN(tried << " R-test catalogue effects hidden and found; invisible at plausible sizes: " << invisible);
  CHECK(tried >= 20);
}
