// SPDX-License-Identifier: BSD-3-Clause
// The one identification result (core/identification.hpp): named blocks, the common part of a
// joint fit's result, the GLS note. Hand-built fit outcomes: the figures are checked against
// formulas written here, not against the code under test.
#include <catch2/catch.hpp>
#include <cmath>

#include "rotacal/core/error.hpp"
#include "rotacal/core/identification.hpp"

using namespace rotacal;

namespace {

// Two location errors, a pivot block of three, one effect parameter.
ParameterLayout small_layout() {
  ParameterLayout L;
  L.add("location_errors", {"X_OC", "Y_OC"}, {"mm"});
  L.add("pivot", {"pivot_x", "pivot_y", "pivot_z"}, {"mm"});
  L.add("effects", {"scale_C"}, {"1"});
  return L;
}

NoiseFit small_fit() {
  NoiseFit nf;
  JointFitOutcome& f = nf.fit;
  for (const std::string& n : small_layout().names())
    f.estimates.push_back({n, 0.1 * static_cast<double>(f.estimates.size() + 1), 0.01, "mm"});
  f.values = Eigen::VectorXd::LinSpaced(6, 0.1, 0.6);
  f.covariance = Eigen::MatrixXd::Identity(6, 6) * 1e-4;
  f.residuals = (Eigen::VectorXd(10) << 1, -2, 3, -4, 5, -6, 7, -8, 9, -10).finished() * 1e-3;
  f.jacobian = Eigen::MatrixXd::Ones(10, 6);
  f.free = {true, true, true, true, true, false};
  f.unobservable = {"scale_C"};
  f.residual_variance = 4e-6;  // (2 um)^2
  f.summary.converged = true;
  f.summary.iterations = 7;
  f.summary.num_free = 5;
  return nf;
}

}  // namespace

TEST_CASE("an identification's named blocks are its parameters' runs in vector order") {
  Identification id = joint_identification(small_fit(), small_layout(), false);
  const std::vector<ParameterEstimate> pivot = id.block("pivot");
  REQUIRE(pivot.size() == 3);
  CHECK(pivot[0].name == "pivot_x");
  CHECK(pivot[2].name == "pivot_z");
  CHECK(pivot[1].value == id.parameter("pivot_y").value);
  CHECK(id.block("effects").front().name == "scale_C");
  CHECK_THROWS_AS(id.block("sphere"), InvalidArgument);
  CHECK_THROWS_WITH(id.parameter("Z_OC"), Catch::Contains("Z_OC"));
  id.parameters.pop_back();  // a layout longer than the estimates is refused, not read past
  CHECK_THROWS_WITH(id.block("effects"), Catch::Contains("effects"));
}

TEST_CASE("the common part of a joint fit's identification") {
  const NoiseFit nf = small_fit();
  const double ss = nf.fit.residuals.squaredNorm();
  const Identification white = joint_identification(nf, small_layout(), false);
  CHECK(white.method == "joint");
  CHECK(white.converged);
  CHECK(white.iterations == 7);
  CHECK(white.residuals.size() == 10);
  CHECK(white.residuals[3] == Approx(-4e-3));
  CHECK(white.residual_rms_um == Approx(std::sqrt(ss / 10.0) * 1e3));
  CHECK(white.sigma_um == Approx(2.0));  // the fit's residual variance, as it was
  CHECK(white.fixed == std::vector<bool>{false, false, false, false, false, true});
  CHECK(white.jacobian.rows() == 10);
  CHECK(white.unobservable == std::vector<std::string>{"scale_C"});
  CHECK_FALSE(white.noise_refit);
  CHECK(white.noise_correction == 1.0);
  // On a whitener (or the GLS refit, or when the instrument asks for it) sigma is the
  // dof-corrected residual sigma: 10 residuals, 5 free parameters.
  const double dof_sigma = std::sqrt(ss / 5.0) * 1e3;
  CHECK(joint_identification(nf, small_layout(), true).sigma_um == Approx(dof_sigma));
  CHECK(joint_identification(nf, small_layout(), false, true).sigma_um == Approx(dof_sigma));
  NoiseFit gls = nf;
  gls.refit = true;
  gls.scale = 1.5;
  const Identification g = joint_identification(gls, small_layout(), false);
  CHECK(g.sigma_um == Approx(dof_sigma));
  CHECK(g.noise_refit);
  CHECK(g.noise_correction == 1.5);
}

TEST_CASE("the GLS note says which noise model the covariance rests on") {
  NoiseFit nf = small_fit();
  CHECK(noise_refit_note(nf).empty());
  nf.refit = true;
  nf.scale = 1.25;
  CHECK_THAT(noise_refit_note(nf), Catch::Contains("scaled by 1.25"));
  nf.reml = true;
  CHECK_THAT(noise_refit_note(nf), Catch::Contains("REML"));
  CHECK_THAT(noise_refit_note(nf), !Catch::Contains("scaled by"));
}
