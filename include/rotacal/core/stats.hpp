// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Tail probabilities for the model-adequacy and model-comparison tests of the diagnosis:
/// chi-square and Fisher F; the Student-t coverage factor of an uncertainty budget. (Eigen and
/// Ceres have none; these are the textbook continued fraction and series of the regularised
/// incomplete gamma and beta functions.)

namespace rotacal::stats {

/// Regularised lower incomplete gamma P(a, x); throws InvalidArgument for a <= 0 or x < 0.
double gamma_p(double a, double x);
/// Regularised incomplete beta I_x(a, b); throws InvalidArgument outside a, b > 0, 0 <= x <= 1.
double beta_i(double a, double b, double x);

/// P(X > x) for X ~ chi-square with k degrees of freedom.
double chi2_sf(double x, double k);
/// P(X > f) for X ~ F(d1, d2).
double f_sf(double f, double d1, double d2);
/// Two-sided Student-t coverage factor: t with P(|T| <= t) = p for nu degrees of freedom
/// (nu may be infinite: the normal quantile). Throws InvalidArgument unless 0 < p < 1, nu > 0.
double t_coverage(double p, double nu);

}  // namespace rotacal::stats
