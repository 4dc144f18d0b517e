// SPDX-License-Identifier: BSD-3-Clause
// The diagnosis on touch-probe data (diagnose/probe_diagnosis.hpp): a stylus whose effective
// radius is 3 um off its calibration is named stylus_radius_offset, with its size; clean data
// name nothing; the candidates' Jacobian agrees with central differences of the probe problem.
#include <catch2/catch.hpp>

#include "rotacal/diagnose/probe_diagnosis.hpp"
#include "rotacal/probe/problem.hpp"
#include "rotacal/probe/simulate.hpp"

using namespace rotacal;

namespace {
ProbeSession session_with(const EffectModel& fx, const std::vector<double>& p, std::uint64_t seed) {
  MachineModel t = MachineModel::nominal(MachineType::AC_trt);
  t.errors.v << 0.0726, -0.0202, 1.1284e-05, -0.000113006, 0.0283, 0.1041, 5.1954e-06, -4.1544e-05;
  t.effects = fx;
  t.effect_params = p;
  ProbeSimOptions o;
  o.pattern = default_probe_pattern(t.machine);
  o.sphere_offset = Eigen::Vector3d(0.01, 0.04, -0.03);
  o.noise_um = 0.5;
  o.seed = seed;
  return simulate_probe(t, o).session;
}
}  // namespace

TEST_CASE("a wrong stylus radius is named stylus_radius_offset", "[diagnose][probe]") {
  const ProbeSession s =
      session_with(EffectModel{{Effect::parse("stylus_radius_offset")}, std::nullopt}, {3e-3}, 21);
  DiagnosisOptions o;
  o.max_harmonic = 2;
  const Diagnosis d = diagnose_probe(s, o);
  REQUIRE_FALSE(d.findings.empty());
  CHECK(d.findings.front().effect.id() == "stylus_radius_offset");
  REQUIRE(d.findings.front().parameters.size() == 1);
  const ParameterEstimate& p = d.findings.front().parameters.front();
  CHECK(std::abs(p.value - 3e-3) <= 3 * p.std);
  const ProbeSession clean = session_with(EffectModel{}, {}, 22);
  CHECK(diagnose_probe(clean, o).findings.empty());
}

TEST_CASE("the probe candidates' Jacobian agrees with central differences", "[diagnose][probe]") {
  const ProbeSession s = session_with(EffectModel{}, {}, 23);
  const ProbeDiagnosisProblem problem(s);
  const ModelFit at = problem.fit(EffectModel{});
  for (const char* id : {"stylus_radius_offset", "probe_lobing", "gravity_sag_A"}) {
    const Effect c = Effect::parse(id);
    const Eigen::MatrixXd J = problem.candidate_jacobian(at, c);
    const ProbeProblem full(s, EffectModel{{c}, std::nullopt});
    Eigen::VectorXd x = Eigen::VectorXd::Zero(full.num_parameters());
    for (std::size_t j = 0; j < at.parameters.size(); ++j)
      x[static_cast<Eigen::Index>(j)] = at.parameters[j].value;
    for (int k = 0; k < c.num_params(); ++k) {
      const Eigen::Index col = static_cast<Eigen::Index>(at.parameters.size()) + k;
      Eigen::VectorXd xp = x, xm = x;
      xp[col] += 1e-6, xm[col] -= 1e-6;
      const Eigen::VectorXd fd = (full.residuals(xp) - full.residuals(xm)) / 2e-6;
      INFO(id << " parameter " << k);
      CHECK((J.col(k) - fd).cwiseAbs().maxCoeff() < 1e-6 * (1 + fd.cwiseAbs().maxCoeff()));
    }
  }
  CHECK(problem.candidates(2).size() > 20);
}
