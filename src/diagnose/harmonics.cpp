// SPDX-License-Identifier: BSD-3-Clause
// Which harmonic orders of a rotary angle a set of readings resolves (Nyquist and aliasing on
// the sampled angles), and why an order is left out, in words.
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/diagnose/diagnosis.hpp"

namespace rotacal {

HarmonicResolution resolve_harmonics(const std::vector<double>& angles_rad, char axis,
                                     int max_order, double min_new_content) {
  if (max_order < 0) throw InvalidArgument("resolve_harmonics: max_order must be >= 0");
  if (!(min_new_content > 0.0 && min_new_content <= 1.0))
    throw InvalidArgument("resolve_harmonics: min_new_content must be in (0, 1]");
  HarmonicResolution R;
  R.axis = axis;
  R.max_order = max_order;
  R.min_new_content = min_new_content;
  if (angles_rad.empty()) {
    R.new_content.assign(static_cast<std::size_t>(max_order), 0.0);
    return R;
  }
  // Distinct angles on the circle: readings at the same commanded angle (or within encoder
  // jitter, 0.05 deg) count once, with their number as weight.
  const double turn = 2.0 * M_PI, same = 0.05 * M_PI / 180.0;
  std::vector<double> a;
  a.reserve(angles_rad.size());
  for (double x : angles_rad) a.push_back(x - turn * std::floor(x / turn));
  std::sort(a.begin(), a.end());
  std::vector<double> at;
  std::vector<double> count;
  for (double x : a) {
    if (!at.empty() && x - at.back() <= same)
      count.back() += 1.0;
    else
      at.push_back(x), count.push_back(1.0);
  }
  if (at.size() > 1 && at.front() + turn - at.back() <= same) {  // wraps past 360 deg
    count.front() += count.back();
    at.pop_back(), count.pop_back();
  }
  const auto N = static_cast<Eigen::Index>(at.size());
  R.distinct_angles = static_cast<int>(N);
  double widest_gap = N > 1 ? 0.0 : turn;
  bool even = N >= 3;
  for (std::size_t i = 0; i < at.size(); ++i) {
    const double gap = i + 1 < at.size() ? at[i + 1] - at[i] : at.front() + turn - at.back();
    widest_gap = std::max(widest_gap, gap);
    even = even && std::abs(gap - turn / static_cast<double>(N)) <= same;
  }
  R.span_deg = (turn - widest_gap) * 180.0 / M_PI;
  if (even) R.even_step_deg = 360.0 / static_cast<double>(N);

  // Weighted design, scaled so that an even full turn gives orthonormal columns.
  const double total = static_cast<double>(angles_rad.size());
  Eigen::MatrixXd H(N, 1 + 2 * max_order);
  for (Eigen::Index i = 0; i < N; ++i) {
    const double w = std::sqrt(count[static_cast<std::size_t>(i)] / total);
    const double th = at[static_cast<std::size_t>(i)];
    H(i, 0) = w;
    for (int k = 1; k <= max_order; ++k) {
      H(i, 2 * k - 1) = w * M_SQRT2 * std::cos(k * th);
      H(i, 2 * k) = w * M_SQRT2 * std::sin(k * th);
    }
  }
  R.resolved = max_order;
  // Orthonormal basis of the span of orders 0..k-1, grown one column at a time by Gram-Schmidt
  // applied twice (orthogonal to rounding); a column with less than 1e-9 of it outside the
  // span is dependent (once an order is unresolvable the lower columns may be) and is left
  // out. A rank-revealing SVD of all lower columns per order took 8 SVDs per call, and the
  // diagnosis calls this for every group several times.
  Eigen::MatrixXd U(N, 1 + 2 * max_order);
  Eigen::Index rank = 0;
  const auto outside = [&](Eigen::MatrixXd C) {
    for (int pass = 0; pass < 2; ++pass) C -= U.leftCols(rank) * (U.leftCols(rank).transpose() * C);
    return C;
  };
  const auto grow = [&](Eigen::Index col) {
    const Eigen::VectorXd v = outside(H.col(col));
    const double norm = v.norm();
    if (norm > 1e-9 * std::max(1.0, H.col(col).norm()) && rank < N) U.col(rank++) = v / norm;
  };
  grow(0);
  for (int k = 1; k <= max_order; ++k) {
    // What of order k lies outside the span of the orders below it.
    const Eigen::MatrixXd rest = outside(H.middleCols(2 * k - 1, 2));
    double nc = 0.0;
    if (N - rank >= 2) {  // two new directions are needed at all (2k + 1 <= N)
      nc = Eigen::JacobiSVD<Eigen::MatrixXd>(rest).singularValues()[1];
      if (nc < 1e-9) nc = 0.0;  // rounding of an exactly dependent pair
    }
    R.new_content.push_back(nc);
    if (nc < min_new_content && R.resolved == max_order) R.resolved = k - 1;
    grow(2 * k - 1);
    grow(2 * k);
  }
  return R;
}

std::string HarmonicResolution::why_not(int order) const {
  std::ostringstream out;
  out.precision(3);
  out << axis << " is sampled at " << distinct_angles << " distinct angle"
      << (distinct_angles == 1 ? "" : "s");
  if (even_step_deg > 0.0)
    out << ", " << even_step_deg << " deg apart over a full turn";
  else
    out << " spanning " << span_deg << " deg";
  if (order <= resolved || order > max_order) {
    out << ": order " << order << " is resolved";
    return out.str();
  }
  const int first = resolved + 1;
  const double nc = new_content[static_cast<std::size_t>(order - 1)];
  if (order > first && nc >= min_new_content) {
    out << ": order " << order << " is left out with the other orders above " << first - 1
        << ", since order " << first << " is not resolvable there";
    return out.str();
  }
  const int N = distinct_angles;
  if (even_step_deg > 0.0 && 2 * order >= N) {
    // Folding on an even grid: cos/sin of order k at th_i = i 2 pi/N equal those of k mod N,
    // and of N - (k mod N) with the sine's sign flipped.
    int alias = order % N;
    if (2 * alias > N) alias = N - alias;
    out << ", which resolves the orders below " << N / 2.0 << " (half the number of angles, the "
        << "Nyquist limit) only: order " << order;
    if (2 * alias == N)
      out << " is that limit: its sine vanishes at every sampled angle, so its amplitude and "
             "phase cannot be told apart";
    else if (alias == 0)
      out << " is constant at every sampled angle (an offset)";
    else
      out << " takes the same values there as order " << alias << " (aliasing)";
    return out.str();
  }
  if (2 * order + 1 > N)
    out << ": order " << order << " needs at least " << 2 * order + 1
        << " distinct angles to be told apart from the lower orders";
  else if (nc == 0.0)
    out << ": there order " << order << " is a combination of the lower orders (aliasing)";
  else
    out << ": there only " << 100.0 * nc << " % of order " << order
        << "'s signature is not a combination of the lower orders (" << 100.0 * min_new_content
        << " % needed)";
  return out.str();
}

}  // namespace rotacal
