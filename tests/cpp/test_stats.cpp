// SPDX-License-Identifier: BSD-3-Clause
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "rotacal/core/error.hpp"
#include "rotacal/core/stats.hpp"

using namespace rotacal;
using Catch::Matchers::WithinRel;

// Reference values from SciPy 1.x (scipy.stats.chi2.sf, scipy.stats.f.sf,
// scipy.special.betainc, scipy.special.gammainc), an independent implementation.
TEST_CASE("chi-square tail matches SciPy", "[stats]") {
  CHECK_THAT(stats::chi2_sf(12.0, 5), WithinRel(0.03478778050624185, 1e-9));
  CHECK_THAT(stats::chi2_sf(1900.0, 1790), WithinRel(0.03490284474449499, 1e-8));
  CHECK_THAT(stats::chi2_sf(0.5, 3), WithinRel(0.9188914116546758, 1e-9));
  CHECK_THAT(stats::chi2_sf(300.0, 200), WithinRel(5.924540335483916e-06, 1e-7));
  CHECK(stats::chi2_sf(-1.0, 3) == 1.0);
}

TEST_CASE("F tail matches SciPy", "[stats]") {
  CHECK_THAT(stats::f_sf(3.0, 2, 1790), WithinRel(0.050037463982537965, 1e-9));
  CHECK_THAT(stats::f_sf(50.0, 4, 1700), WithinRel(7.898500270606594e-40, 1e-6));
  CHECK_THAT(stats::f_sf(0.7, 1, 30), WithinRel(0.4093989886440107, 1e-9));
  CHECK_THAT(stats::f_sf(1.2, 10, 12), WithinRel(0.376953125, 1e-9));
}

TEST_CASE("incomplete beta and gamma match SciPy; bad arguments throw", "[stats]") {
  CHECK_THAT(stats::beta_i(2.5, 3.5, 0.3), WithinRel(0.29675298929566646, 1e-10));
  CHECK_THAT(stats::gamma_p(3.0, 2.0), WithinRel(0.32332358381693654, 1e-10));
  CHECK_THROWS_AS(stats::beta_i(-1.0, 2.0, 0.5), InvalidArgument);
  CHECK_THROWS_AS(stats::gamma_p(1.0, -2.0), InvalidArgument);
  CHECK_THROWS_AS(stats::f_sf(1.0, 0.0, 3.0), InvalidArgument);
  // 0/0 (residuals exactly zero, as identical rows give on some CPUs): undetermined, not a throw.
  CHECK(std::isnan(stats::f_sf(std::nan(""), 2, 100)));
  CHECK(stats::f_sf(std::numeric_limits<double>::infinity(), 2, 100) == 0.0);
}

// Reference values from scipy.stats.t.ppf(0.975, nu) and scipy.stats.norm.ppf(0.975).
TEST_CASE("Student-t coverage factor matches SciPy", "[stats]") {
  CHECK_THAT(stats::t_coverage(0.95, 1), WithinRel(12.706204736174694, 1e-8));
  CHECK_THAT(stats::t_coverage(0.95, 10), WithinRel(2.2281388519862744, 1e-8));
  CHECK_THAT(stats::t_coverage(0.95, 50.5), WithinRel(2.0080664982950434, 1e-8));
  CHECK_THAT(stats::t_coverage(0.95, std::numeric_limits<double>::infinity()),
             WithinRel(1.959963984540054, 1e-8));
  CHECK_THROWS_WITH(stats::t_coverage(1.5, 3), Catch::Contains("p is 1.5"));
  CHECK_THROWS_AS(stats::t_coverage(0.95, 0), InvalidArgument);
}
