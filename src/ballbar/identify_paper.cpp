// SPDX-License-Identifier: BSD-3-Clause
// Flynn et al.'s geometric identification chain: sphere, circle and plane fits, then transport.
#include "rotacal/ballbar/identify_paper.hpp"

#include <cmath>

#include "rotacal/fit/circle.hpp"
#include "rotacal/fit/plane.hpp"
#include "rotacal/fit/sphere.hpp"

namespace rotacal {

namespace {

struct AxisEstimate {
  Eigen::Vector3d point;      // a point of the average line (in the pivot's plane of rotation)
  Eigen::Vector3d direction;  // unit
};

// Indices of one test; throws if it is missing.
std::vector<std::size_t> need(const BallbarSession& s, const std::string& test) {
  const std::vector<std::size_t> idx = s.indices_of(test);
  if (idx.empty())
    throw InvalidArgument("identify_paper: the session has no '" + test +
                          "' test (the paper's chain needs sphere_xy, sphere_yz, sphere_zx and the "
                          "radial and axial tests of both rotary axes)");
  return idx;
}

// Pivot estimates along the nominal bar direction (Eq. 2): x_CP from the nominal kinematics
// of the (sphere-fitted) pivot, u_BB towards it from the tool, at the measured length.
Points3 pivot_estimates(const BallbarSession& s, const std::vector<std::size_t>& idx,
                        const Eigen::Vector3d& pivot, Points3* nominal) {
  const LocationErrors<double> zero;
  Points3 out(static_cast<Eigen::Index>(idx.size()), 3);
  nominal->resize(static_cast<Eigen::Index>(idx.size()), 3);
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const BallbarSample& b = s.samples[idx[k]];
    const Eigen::Vector3d x_cp = forward(s.machine, zero, b.angles_rad(), pivot);
    const Eigen::Vector3d u_bb = (x_cp - b.xyz).normalized();
    out.row(static_cast<Eigen::Index>(k)) = (b.xyz + b.length * u_bb).transpose();
    nominal->row(static_cast<Eigen::Index>(k)) = x_cp.transpose();
  }
  return out;
}

// Axis index of the rotary axis: 0 for A (X), 1 for B (Y), 2 for C (Z).
AxisEstimate axis_from_tests(const BallbarSession& s, const std::string& radial,
                             const std::string& axial, int k, const Eigen::Vector3d& pivot,
                             CircleFit* circle, PlaneFit* plane) {
  const int i1 = (k + 1) % 3, i2 = (k + 2) % 3;  // the plane of rotation, cyclic order
  Points3 nominal;
  // 3.2: radial test -> centre of rotation in the plane perpendicular to the axis.
  const Points3 pr = pivot_estimates(s, need(s, radial), pivot, &nominal);
  Points2 in_plane(pr.rows(), 2);
  in_plane.col(0) = pr.col(i1);
  in_plane.col(1) = pr.col(i2);
  CircleFitOptions circle_options;
  circle_options.context = "test " + radial;  // a refused fit names the test it came from
  *circle = hyper_circle_fit(in_plane, circle_options);
  // 3.3: axial test -> the radial coordinates stay nominal, the axial one comes from the bar.
  Points3 pa = pivot_estimates(s, need(s, axial), pivot, &nominal);
  pa.col(i1) = nominal.col(i1);
  pa.col(i2) = nominal.col(i2);
  *plane = svd_plane_fit(pa, Eigen::Vector3d::Unit(k), 0.0, "test " + axial);
  AxisEstimate a;
  a.point[k] = pivot[k];
  a.point[i1] = circle->centre.x();
  a.point[i2] = circle->centre.y();
  a.direction = plane->normal;
  return a;
}

// The eight location errors from the two estimated lines (formats.md definitions), with the
// lines transported to the nominal intersection (the machine origin).
Eigen::Matrix<double, 8, 1> location_errors(MachineType m, const AxisEstimate& T,
                                            const AxisEstimate& C) {
  Eigen::Matrix<double, 8, 1> e;
  if (m == MachineType::AC_trt) {
    const Eigen::Vector3d d = T.direction / T.direction.x();  // (1, E_C0A, -E_B0A)
    const Eigen::Vector3d p0 = T.point - T.point.x() * d;     // where the line meets x = 0
    e[0] = p0.y(), e[1] = p0.z(), e[2] = -d.z(), e[3] = d.y();
  } else {
    const Eigen::Vector3d d = T.direction / T.direction.y();  // (-E_C0B, 1, E_A0B)
    const Eigen::Vector3d p0 = T.point - T.point.y() * d;     // where it meets y = 0
    e[0] = p0.x(), e[1] = p0.z(), e[2] = d.z(), e[3] = -d.x();
  }
  const Eigen::Vector3d d = C.direction / C.direction.z();  // (E_B0C, -E_A0C, 1)
  const Eigen::Vector3d p0 = C.point - C.point.z() * d;     // where it meets z = 0
  e[4] = p0.x(), e[5] = p0.y(), e[6] = -d.y(), e[7] = d.x();
  return e;
}

}  // namespace

BallbarIdentification identify_paper(const BallbarSession& s, bool with_residuals) {
  const MachineType m = s.machine;
  if (m != MachineType::AC_trt && m != MachineType::BC_trt)
    throw InvalidArgument(
        "identify_paper: Flynn et al.'s chain is written for the AC-trt and BC-trt "
        "tables; the " +
        to_string(m) +
        " machine is identified by the joint fit "
        "(identify_joint, --method joint)");
  const char T = tilt_axis_letter(m);
  const int k_tilt = m == MachineType::AC_trt ? 0 : 1;

  // 3.1: pivot from the arcs at rotary zero. Each reading, put along the nominal bar direction
  // from the nominal pivot, is where the tool appears to be seen from there: those points lie
  // on a sphere of radius L0 about the nominal pivot mirrored through the actual one.
  std::vector<std::size_t> sphere_idx;
  for (const char* t : {"sphere_xy", "sphere_yz", "sphere_zx"}) {
    const auto idx = need(s, t);
    sphere_idx.insert(sphere_idx.end(), idx.begin(), idx.end());
  }
  Points3 q(static_cast<Eigen::Index>(sphere_idx.size()), 3);
  for (std::size_t k = 0; k < sphere_idx.size(); ++k) {
    const BallbarSample& b = s.samples[sphere_idx[k]];
    q.row(static_cast<Eigen::Index>(k)) =
        (s.pivot + (b.xyz - s.pivot).normalized() * b.length).transpose();
  }
  SphereFitOptions so;
  so.radius = s.ballbar_length;
  const SphereFit sphere = sphere_fit(q, so);
  const Eigen::Vector3d pivot = 2.0 * s.pivot - sphere.centre;

  CircleFit circle_t, circle_c;
  PlaneFit plane_t, plane_c;
  const std::string tl(1, T);
  const AxisEstimate at =
      axis_from_tests(s, "radial_" + tl, "axial_" + tl, k_tilt, pivot, &circle_t, &plane_t);
  const AxisEstimate ac = axis_from_tests(s, "radial_C", "axial_C", 2, pivot, &circle_c, &plane_c);
  const Eigen::Matrix<double, 8, 1> e = location_errors(m, at, ac);

  // First-order propagation: the 8 errors and the pivot as functions of the fitted
  // quantities (pivot 3, circle centres 2 + 2, normals 3 + 3), finite-difference Jacobian.
  Eigen::Matrix<double, 13, 1> theta;
  theta << pivot, circle_t.centre, plane_t.normal, circle_c.centre, plane_c.normal;
  auto chain = [&](const Eigen::Matrix<double, 13, 1>& th) {
    const int i1 = (k_tilt + 1) % 3, i2 = (k_tilt + 2) % 3;
    AxisEstimate a, c;
    a.point[k_tilt] = th[k_tilt];
    a.point[i1] = th[3], a.point[i2] = th[4];
    a.direction = th.segment<3>(5);
    c.point = Eigen::Vector3d(th[8], th[9], th[2]);
    c.direction = th.segment<3>(10);
    Eigen::Matrix<double, 11, 1> out;
    out << location_errors(m, a, c), th.head<3>();
    return out;
  };
  Eigen::Matrix<double, 13, 13> Sigma = Eigen::Matrix<double, 13, 13>::Zero();
  Sigma.block<3, 3>(0, 0) = sphere.covariance.topLeftCorner<3, 3>();  // pivot = 2 P0 - centre
  Sigma.block<2, 2>(3, 3) = circle_t.covariance.topLeftCorner<2, 2>();
  Sigma.block<3, 3>(5, 5) = plane_t.normal_covariance;
  Sigma.block<2, 2>(8, 8) = circle_c.covariance.topLeftCorner<2, 2>();
  Sigma.block<3, 3>(10, 10) = plane_c.normal_covariance;
  Eigen::Matrix<double, 11, 13> J;
  for (int j = 0; j < 13; ++j) {
    const double h = j < 3 || (j >= 3 && j < 5) || (j >= 8 && j < 10) ? 1e-6 : 1e-9;
    Eigen::Matrix<double, 13, 1> tp = theta, tm = theta;
    tp[j] += h, tm[j] -= h;
    J.col(j) = (chain(tp) - chain(tm)) / (2 * h);
  }
  const Eigen::Matrix<double, 11, 11> cov = J * Sigma * J.transpose();

  BallbarIdentification out;
  out.method = "paper";
  out.model.machine = m;
  out.model.errors = LocationErrors<double>(e);
  out.model.pivot = pivot;
  out.covariance = cov;
  out.converged = sphere.converged;
  out.n_samples = s.samples.size();
  for (int j = 0; j < 11; ++j) {
    ParameterEstimate p;
    p.name = j < 8 ? location_error_names(m)[static_cast<std::size_t>(j)]
                   : std::string("pivot_") + "xyz"[j - 8];
    p.unit = j < 8 && location_error_is_angle(j) ? "rad" : "mm";
    p.value = j < 8 ? e[j] : pivot[j - 8];
    p.std = std::sqrt(std::max(0.0, cov(j, j)));
    out.parameters.push_back(p);
  }
  // Residuals of the identified model on every sample, as for the joint fit.
  if (with_residuals) {
    const std::vector<double> L = predict_lengths(out.model, s.samples);
    double ss = 0.0;
    for (std::size_t i = 0; i < L.size(); ++i) {
      out.residuals.push_back(s.samples[i].length - L[i]);
      ss += out.residuals.back() * out.residuals.back();
    }
    out.residual_rms_um = std::sqrt(ss / static_cast<double>(L.size())) * 1e3;
    out.sigma_um = out.residual_rms_um;
  }
  out.notes = {
      "Flynn et al. 2016, Sec. 3: sphere fit (radius L0), Hyper circle fits of the radial tests, "
      "SVD plane fits of the axial tests, lines transported to the nominal intersection",
      "assumes small errors: each pivot estimate lies along the nominal bar direction (Eq. 2); "
      "in the axial tests the pivot's radial coordinates are taken as nominal",
      "the pivot is found to first order (the sphere fit sees it mirrored through the nominal "
      "pivot): second-order error ~ offset^2 / L0",
      "uncertainties: first-order propagation of the fits' covariances, which treat the fits as "
      "independent"};
  return out;
}

}  // namespace rotacal
