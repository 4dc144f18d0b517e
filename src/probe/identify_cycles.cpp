// SPDX-License-Identifier: BSD-3-Clause
// The controller cycles' method on touch-probe data (HEIDENHAIN KinematicsOpt cycle 451,
// ISG SysMeasRotAx), as the peer of the joint fit: sphere per pose, then per table axis a
// plane (Flynn et al. 2016, Eq. 3) and a circle (hyper fit, Al-Sharadqah & Chernov 2009)
// through the centres of the poses that turn that axis alone.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "rotacal/fit/circle.hpp"
#include "rotacal/fit/plane.hpp"
#include "rotacal/fit/sphere.hpp"
#include "rotacal/probe/identify.hpp"

namespace rotacal {

namespace {

struct PoseCentre {
  std::string label;
  RotaryAngles<double> angles_deg;
  Eigen::Vector3d centre;
  double rms = 0.0;  // of its sphere fit, mm
};

// A pose's centre resting on the noise in one direction (its Jacobian's condition number
// beyond this: the std there 100 times the best one's) is refused, naming the pose.
constexpr double kMaxPoseCondition = 100.0;
// An axis whose poses' centres circle it less than this many noise sigmas in radius leaves
// its direction and position to the noise: reported unobservable, as the joint fit does.
constexpr double kMinCircleToNoise = 200.0;
// The noise floor of that judgement (mm): noise-free simulated touches still set a scale.
constexpr double kNoiseFloorMm = 1e-4;

// Sphere fit of each pose's touches (the stylus-tip centres: on a table-table machine the
// latched X, Y, Z themselves).
std::vector<PoseCentre> pose_centres(const ProbeSession& s, const ProbeCyclesOptions& o) {
  std::vector<PoseCentre> out;
  for (const std::string& pose : s.poses()) {
    const std::vector<std::size_t> idx = s.indices_of(pose);
    Points3 P(static_cast<Eigen::Index>(idx.size()), 3);
    for (std::size_t k = 0; k < idx.size(); ++k)
      P.row(static_cast<Eigen::Index>(k)) = s.samples[idx[k]].xyz;
    SphereFitOptions so;
    if (o.radius_known) so.radius = s.trigger_radius();
    so.max_condition = kMaxPoseCondition;
    try {
      const SphereFit f = sphere_fit(P, so);
      const ProbeSample& first = s.samples[idx.front()];
      out.push_back({pose, {first.tilt_deg, first.rot_deg}, f.centre, f.rms});
    } catch (const DegenerateGeometry& e) {
      throw DegenerateGeometry("identify_probe_cycles: pose '" + pose + "': " + e.what());
    }
  }
  return out;
}

struct AxisFit {
  Eigen::Vector3d direction;   // unit, towards the nominal direction
  Eigen::Vector3d point;       // circle centre, on the axis line
  double dispersion_sq = 0.0;  // sum of squared distances of the centres from the circle
  int n = 0;
  double radius = 0.0;  // of the circle of the centres, mm
};

// Plane and circle through the centres of the poses that turn chain axis k alone (the other
// axis at 0).
AxisFit fit_axis(MachineType m, int k, const std::vector<PoseCentre>& centres) {
  const RotaryAxis& a = m.description().axis(k);
  const int other = 1 - k;
  std::vector<Eigen::Vector3d> pts;
  for (const PoseCentre& c : centres)
    if (std::abs(chain_angle(m, c.angles_deg, other)) < 1e-9) pts.push_back(c.centre);
  const std::string what = std::string("identify_probe_cycles: axis ") + a.name;
  if (pts.size() < 3)
    throw DegenerateGeometry(what + ": " + std::to_string(pts.size()) +
                             " poses turn it alone (with " + m.description().axis(other).name +
                             " at 0); the cycles need at least 3");
  Points3 P(static_cast<Eigen::Index>(pts.size()), 3);
  for (std::size_t i = 0; i < pts.size(); ++i) P.row(static_cast<Eigen::Index>(i)) = pts[i];
  const PlaneFit plane = svd_plane_fit(P, a.direction, 0.0, what);
  AxisFit out;
  out.direction = plane.normal;
  const Eigen::Vector3d u = (a.radial1 - a.radial1.dot(out.direction) * out.direction).normalized();
  const Eigen::Vector3d v = out.direction.cross(u);
  Points2 Q(P.rows(), 2);
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d d = P.row(i).transpose() - plane.centroid;
    Q(i, 0) = d.dot(u);
    Q(i, 1) = d.dot(v);
  }
  CircleFitOptions co;
  co.context = what;
  const CircleFit circle = hyper_circle_fit(Q, co);
  out.point = plane.centroid + circle.centre.x() * u + circle.centre.y() * v;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d d = P.row(i).transpose() - out.point;
    const double axial = d.dot(out.direction);
    const double radial = (d - axial * out.direction).norm() - circle.radius;
    out.dispersion_sq += axial * axial + radial * radial;
  }
  out.n = static_cast<int>(P.rows());
  out.radius = circle.radius;
  return out;
}

// The four location errors of axis k from its fitted line: direction n / (n . n0) = n0 + N e23,
// and the line's point where it crosses the plane through p0 normal to n0 = p0 + P e01.
Eigen::Vector4d axis_errors(const RotaryAxis& a, const AxisFit& f) {
  const Eigen::Vector3d n0 = a.direction;
  const double along = f.direction.dot(n0);
  const Eigen::Vector3d dn = f.direction / along - n0;
  const double lambda = -(f.point - a.point).dot(n0) / along;
  const Eigen::Vector3d dp = f.point + lambda * f.direction - a.point;
  Eigen::Vector4d e;
  e.head<2>() = a.position_basis.transpose() * dp;
  e.tail<2>() = a.direction_basis.transpose() * dn;
  return e;
}

}  // namespace

ProbeIdentification identify_probe_cycles(const ProbeSession& s, const ProbeCyclesOptions& o) {
  const MachineType m = s.machine;
  const MachineDescription& d = m.description();
  if (d.has_head() || d.table_axes.size() != 2)
    throw InvalidArgument(
        "identify_probe_cycles: " + to_string(m) +
        ": the cycles' method measures two table axes; use identify_probe (the joint fit) on "
        "a machine with head axes");
  const std::vector<PoseCentre> centres = pose_centres(s, o);
  ProbeIdentification out;
  out.method = "cycles";
  out.model.machine = m;
  double dispersion_sq = 0.0, noise_sq = 0.0;
  int n_disp = 0;
  for (const PoseCentre& c : centres) noise_sq += c.rms * c.rms;
  const double noise =
      std::max(kNoiseFloorMm, std::sqrt(noise_sq / static_cast<double>(centres.size())));
  std::array<bool, 2> seen{true, true};
  for (int k = 0; k < 2; ++k) {
    const AxisFit f = fit_axis(m, k, centres);
    dispersion_sq += f.dispersion_sq;
    n_disp += f.n;
    if (!(f.radius >= kMinCircleToNoise * noise)) {  // the sphere on or near this axis
      seen[static_cast<std::size_t>(k)] = false;
      out.unobservable.push_back(
          std::string("axis ") + d.axis(k).name +
          ": the sphere centres of the poses that turn "
          "it circle it with a radius of " +
          std::to_string(f.radius) + " mm, under " + std::to_string(kMinCircleToNoise) +
          " times the touches' noise (" + std::to_string(noise * 1e3) +
          " um): the sphere sits on or near the axis, so its "
          "direction and position are not determined (move the sphere off the axis)");
      continue;
    }
    out.model.errors.v.segment<4>(4 * k) = axis_errors(d.axis(k), f);
  }
  out.dispersion_um = std::sqrt(dispersion_sq / std::max(1, n_disp)) * 1e3;
  const auto& names = location_error_names(m);
  for (int k = 0; k < 8; ++k)
    out.parameters.push_back({names[static_cast<std::size_t>(k)], out.model.errors.v[k],
                              std::numeric_limits<double>::quiet_NaN(),
                              location_error_is_angle(k) ? "rad" : "mm",
                              seen[static_cast<std::size_t>(k / 4)]});
  // The sphere on the table: each pose's centre taken back by the identified table motion.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const PoseCentre& c : centres) {
    const RotaryAngles<double> a{c.angles_deg.tilt * M_PI / 180.0, c.angles_deg.rot * M_PI / 180.0};
    sum += table_pose<double>(m, out.model.errors, a).inverse() * c.centre;
    out.pose_centres.push_back(c.centre);
    out.pose_labels.push_back(c.label);
  }
  out.sphere = sum / static_cast<double>(centres.size());
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    std::size_t p = 0;
    while (out.pose_labels[p] != s.samples[i].pose) ++p;
    out.residuals.push_back(s.trigger_radius() - (s.samples[i].xyz - out.pose_centres[p]).norm());
  }
  double ss = 0.0;
  for (double r : out.residuals) ss += r * r;
  out.residual_rms_um = std::sqrt(ss / std::max<std::size_t>(1, out.residuals.size())) * 1e3;
  out.n_samples = s.samples.size();
  out.converged = true;
  out.notes.push_back(
      std::string("cycles' method: sphere per pose (radius ") +
      (o.radius_known ? "known" : "free") +
      "), plane and circle of the centres per table axis; no uncertainty (std NaN), the "
      "dispersion of the centres about the circles instead");
  return out;
}

}  // namespace rotacal
