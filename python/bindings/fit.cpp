// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/fit.
#include "numpy.hpp"
#include "rotacal/fit/box_least_squares.hpp"
#include "rotacal/fit/circle.hpp"
#include "rotacal/fit/plane.hpp"
#include "rotacal/fit/sphere.hpp"

namespace rotacal::py {

void bind_fit(pyb::module_& m) {
  pyb::class_<CircleFit>(m, "CircleFit")
      .def_readonly("centre", &CircleFit::centre)
      .def_readonly("radius", &CircleFit::radius)
      .def_readonly("covariance", &CircleFit::covariance, "(cx, cy, r), 1-sigma^2")
      .def_readonly("rms", &CircleFit::rms)
      .def_readonly("n", &CircleFit::n);
  pyb::class_<SphereFit>(m, "SphereFit")
      .def_readonly("centre", &SphereFit::centre)
      .def_readonly("radius", &SphereFit::radius)
      .def_readonly("covariance", &SphereFit::covariance, "(cx, cy, cz, r), 1-sigma^2")
      .def_readonly("rms", &SphereFit::rms)
      .def_readonly("n", &SphereFit::n)
      .def_readonly("converged", &SphereFit::converged);
  pyb::class_<PlaneFit>(m, "PlaneFit")
      .def_readonly("centroid", &PlaneFit::centroid)
      .def_readonly("normal", &PlaneFit::normal)
      .def_readonly("singular_values", &PlaneFit::singular_values)
      .def_readonly("normal_covariance", &PlaneFit::normal_covariance)
      .def_readonly("rms", &PlaneFit::rms)
      .def_readonly("n", &PlaneFit::n);

  const char* circle_doc = R"doc(Circle fit to (N, 2) points.

Parameters
----------
points : (N, 2) array
sigma : known 1-sigma noise of the points (0: estimated from the residuals)
refine : polish by orthogonal distances (Ceres)

Raises rotacal.DegenerateGeometry for < 3, collinear points or a too short arc.)doc";
  m.def(
      "hyper_circle_fit",
      [](const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& points,
         double sigma, bool refine) {
        CircleFitOptions o;
        o.sigma = sigma;
        o.refine = refine;
        return hyper_circle_fit(rows_of<2>(points, "points"), o);
      },
      pyb::arg("points"), pyb::arg("sigma") = 0.0, pyb::arg("refine") = false, circle_doc);
  m.def(
      "kasa_circle_fit",
      [](const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& points,
         double sigma, bool refine) {
        CircleFitOptions o;
        o.sigma = sigma;
        o.refine = refine;
        return kasa_circle_fit(rows_of<2>(points, "points"), o);
      },
      pyb::arg("points"), pyb::arg("sigma") = 0.0, pyb::arg("refine") = false, circle_doc);
  m.def(
      "sphere_fit",
      [](const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& points,
         std::optional<double> radius,
         double sigma) { return sphere_fit(rows_of<3>(points, "points"), {radius, sigma}); },
      pyb::arg("points"), pyb::arg("radius") = std::nullopt, pyb::arg("sigma") = 0.0,
      "Least-squares sphere to (N, 3) points; radius fixes it (e.g. the ballbar length).");
  m.def(
      "svd_plane_fit",
      [](const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& points,
         const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& normal_hint,
         double sigma) {
        return svd_plane_fit(rows_of<3>(points, "points"), vec_of<3>(normal_hint, "normal_hint"),
                             sigma);
      },
      pyb::arg("points"),
      pyb::arg("normal_hint") = pyb::array_t<double>(3, std::array<double, 3>{0, 0, 1}.data()),
      pyb::arg("sigma") = 0.0, "Total-least-squares plane (Flynn et al. Eq. 3).");
  m.def(
      "box_least_squares",
      [](const Eigen::MatrixXd& R, const Eigen::VectorXd& d, const Eigen::VectorXd& w,
         const Eigen::VectorXd& bounds, int max_sweeps,
         double tolerance) { return box_least_squares(R, d, w, bounds, {max_sweeps, tolerance}); },
      pyb::arg("R"), pyb::arg("d"), pyb::arg("w"), pyb::arg("bounds"), pyb::arg("max_sweeps") = 200,
      pyb::arg("tolerance") = 1e-9,
      R"doc(min sum w (d - R s)^2 with abs(s_j) <= bounds_j, by cyclic coordinate descent.

Parameters
----------
R : (N, K) array
d, w : (N,) arrays, w >= 0
bounds : (K,) array, >= 0
max_sweeps, tolerance : stop after max_sweeps passes, or when no s_j moves by more than
    tolerance * bounds_j

Returns s (K,). Raises rotacal.InvalidArgument for mismatched sizes or non-finite input.)doc");
}

}  // namespace rotacal::py
