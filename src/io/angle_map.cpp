// SPDX-License-Identifier: BSD-3-Clause
// An axis' error functions sampled at equally spaced angles, with the worst interpolation error
// between the points (the functions: compensation/axis_errors.cpp).
#include "rotacal/io/angle_map.hpp"

#include <cmath>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal {

std::vector<double> equally_spaced_deg(double lo_deg, double hi_deg, double spacing_deg,
                                       const std::string& option) {
  if (!(std::isfinite(lo_deg) && std::isfinite(hi_deg) && hi_deg > lo_deg))
    throw InvalidArgument(option + ": the range " + std::to_string(lo_deg) + ".." +
                          std::to_string(hi_deg) + " deg must run upwards");
  if (!(std::isfinite(spacing_deg) && spacing_deg > 0.0))
    throw InvalidArgument(option + ": the spacing must be > 0 deg");
  const double steps = (hi_deg - lo_deg) / spacing_deg;
  const double whole = std::round(steps);
  if (std::abs(steps - whole) > 1e-9 * std::max(1.0, steps))
    throw InvalidArgument(option + ": " + std::to_string(hi_deg - lo_deg) +
                          " deg is not a whole number of " + std::to_string(spacing_deg) +
                          " deg spacings");
  if (whole > 1e6) throw InvalidArgument(option + ": more than 10^6 points");
  std::vector<double> g;
  for (int i = 0; i <= static_cast<int>(whole); ++i) g.push_back(lo_deg + i * spacing_deg);
  return g;
}

double worst_interpolation_error(const std::vector<double>& grid,
                                 const std::vector<double>& at_grid,
                                 const std::function<double(double)>& f, int samples_between) {
  double worst = 0.0;
  // From each interval's first point on (a table's values may be rounded there), and the last.
  if (!grid.empty()) worst = std::abs(f(grid.back()) - at_grid.back());
  for (std::size_t i = 0; i + 1 < grid.size(); ++i)
    for (int s = 0; s <= samples_between; ++s) {
      const double u = static_cast<double>(s) / (samples_between + 1);
      const double x = grid[i] + u * (grid[i + 1] - grid[i]);
      const double lin = at_grid[i] + u * (at_grid[i + 1] - at_grid[i]);
      worst = std::max(worst, std::abs(f(x) - lin));
    }
  return worst;
}

AxisAngleMap sample_angle_map(const AxisErrorFunction& f, double lo_deg, double hi_deg,
                              double spacing_deg, int samples_between) {
  if (samples_between < 1) throw InvalidArgument("sample_angle_map: samples_between must be >= 1");
  AxisAngleMap map;
  map.axis = f.axis;
  map.lo_deg = lo_deg;
  map.hi_deg = hi_deg;
  map.spacing_deg = spacing_deg;
  map.names = f.names;
  map.units = f.units;
  map.sources = f.sources;
  map.notes = f.notes;
  map.samples_between = samples_between;
  map.angle_deg =
      equally_spaced_deg(lo_deg, hi_deg, spacing_deg, std::string("the ") + f.axis + " table");
  const auto n = static_cast<Eigen::Index>(map.angle_deg.size());
  map.values.resize(n, kAngleMapTerms);
  for (Eigen::Index i = 0; i < n; ++i)
    map.values.row(i) = f.evaluate(map.angle_deg[static_cast<std::size_t>(i)] * kDeg).transpose();
  map.max_abs = map.values.cwiseAbs().colwise().maxCoeff().transpose();
  // Every term from one evaluation per angle between the points.
  for (Eigen::Index i = 0; i + 1 < n; ++i)
    for (int s = 1; s <= samples_between; ++s) {
      const double u = static_cast<double>(s) / (samples_between + 1);
      const std::size_t a = static_cast<std::size_t>(i);
      const double deg = map.angle_deg[a] + u * (map.angle_deg[a + 1] - map.angle_deg[a]);
      const AngleMapTerms lin =
          (map.values.row(i) + u * (map.values.row(i + 1) - map.values.row(i))).transpose();
      map.max_interpolation_error =
          map.max_interpolation_error.cwiseMax((f.evaluate(deg * kDeg) - lin).cwiseAbs());
    }
  return map;
}

}  // namespace rotacal
