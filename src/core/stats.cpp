// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/core/stats.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "rotacal/core/error.hpp"

namespace rotacal::stats {

namespace {
constexpr double kEps = 1e-15;
constexpr double kTiny = 1e-300;
constexpr int kMaxIter = 1000;

// Continued fraction for the upper incomplete gamma Q(a, x), x >= a + 1 (modified Lentz).
double gamma_q_cf(double a, double x) {
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i <= kMaxIter; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < kEps) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// Series for P(a, x), x < a + 1.
double gamma_p_series(double a, double x) {
  double ap = a, del = 1.0 / a, sum = del;
  for (int i = 0; i < kMaxIter; ++i) {
    ap += 1.0;
    del *= x / ap;
    sum += del;
    if (std::abs(del) < std::abs(sum) * kEps) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Continued fraction of the incomplete beta (modified Lentz).
double beta_cf(double a, double b, double x) {
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0, d = 1.0 - qab * x / qap;
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= kMaxIter; ++m) {
    const int m2 = 2 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < kEps) break;
  }
  return h;
}
}  // namespace

double gamma_p(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) throw InvalidArgument("gamma_p: need a > 0 and x >= 0");
  if (x == 0.0) return 0.0;
  return x < a + 1.0 ? gamma_p_series(a, x) : 1.0 - gamma_q_cf(a, x);
}

double beta_i(double a, double b, double x) {
  if (!(a > 0.0) || !(b > 0.0) || !(x >= 0.0 && x <= 1.0))
    throw InvalidArgument("beta_i: need a, b > 0 and 0 <= x <= 1");
  if (x == 0.0 || x == 1.0) return x;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  // The continued fraction converges fast for x < (a + 1) / (a + b + 2); use symmetry else.
  if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_cf(a, b, x) / a;
  return 1.0 - front * beta_cf(b, a, 1.0 - x) / b;
}

double chi2_sf(double x, double k) {
  if (x <= 0.0) return 1.0;
  const double a = 0.5 * k, y = 0.5 * x;
  return y < a + 1.0 ? 1.0 - gamma_p_series(a, y) : gamma_q_cf(a, y);
}

double f_sf(double f, double d1, double d2) {
  if (!(d1 > 0.0) || !(d2 > 0.0)) throw InvalidArgument("f_sf: degrees of freedom must be > 0");
  // An undetermined statistic (0/0 from residuals that are exactly zero) has an undetermined
  // p-value: NaN, which no threshold passes and JSON writes as null with its reason.
  if (std::isnan(f)) return f;
  if (f <= 0.0) return 1.0;
  // P(F > f) = I_{d2 / (d2 + d1 f)}(d2 / 2, d1 / 2)
  return beta_i(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
}

double t_coverage(double p, double nu) {
  if (!(p > 0.0 && p < 1.0))
    throw InvalidArgument("t_coverage: p is " + std::to_string(p) + ", must be in (0, 1)");
  if (!(nu > 0.0))
    throw InvalidArgument("t_coverage: nu is " + std::to_string(nu) + ", must be > 0");
  // P(|T| > t) = I_{nu/(nu+t^2)}(nu/2, 1/2); for nu beyond 1e7 the normal limit,
  // P(|Z| > z) = erfc(z / sqrt 2). Bisection: both tails fall monotonically in t.
  const auto tail = [nu](double t) {
    return nu > 1e7 ? std::erfc(t / std::sqrt(2.0)) : beta_i(nu / 2.0, 0.5, nu / (nu + t * t));
  };
  double lo = 0.0, hi = 1.0;
  while (tail(hi) > 1.0 - p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (tail(mid) > 1.0 - p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace rotacal::stats
