// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The geometric (orthogonal distance) refinement of the circle and sphere fits: one definition
// of the residual, two solvers of the same sum of squares. Ceres' solver in the default build;
// in a build configured with -DROTACAL_CERES_SOLVER=OFF rotacal's own joint-fit driver
// (core/joint_fit.hpp), so that the library links no Ceres library, only Ceres' header-only
// Jets (docs/licensing.md: Debian's libceres brings SuiteSparse, parts of which are GPL-2.0+).
// The two agree to far inside the fits' uncertainty (tests/cpp/test_fit_orthogonal_distance.cpp).

#include <Eigen/Core>

namespace rotacal {

template <int Dim>
using PointRows = Eigen::Matrix<double, Eigen::Dynamic, Dim, Eigen::RowMajor>;

/// r = |p - centre| - radius for one point p of dimension Dim (2: circle, 3: sphere), in the
/// Ceres cost-functor shape (parameter blocks: centre, radius), with T = double or a Jet.
template <int Dim>
struct OrthogonalDistance {
  explicit OrthogonalDistance(const Eigen::Matrix<double, Dim, 1>& p) : p_(p) {}
  template <typename T>
  bool operator()(const T* centre, const T* radius, T* residual) const {
    using std::sqrt;
    T squared(0.0);
    for (int k = 0; k < Dim; ++k) {
      const T d = T(p_[k]) - centre[k];
      squared += d * d;
    }
    residual[0] = sqrt(squared) - radius[0];
    return true;
  }
  Eigen::Matrix<double, Dim, 1> p_;
};

enum class DistanceSolver {
  built,  ///< Ceres' where the library was built with it (ROTACAL_CERES_SOLVER), else joint
  ceres,  ///< Ceres' solver; InvalidArgument in a build without it
  joint,  ///< rotacal's joint-fit driver (core/joint_fit.hpp), in every build
};

/// Whether this build of the library has Ceres' solver (-DROTACAL_CERES_SOLVER=ON).
bool ceres_solver_built();

/// Moves (centre, radius) from a start near the solution (the algebraic fit) to the minimum of
/// sum_i (|p_i - centre| - radius)^2 over the rows p_i of `points`; the radius is held when
/// `fix_radius`. Returns whether the solver reports convergence.
template <int Dim>
bool refine_orthogonal_distance(const Eigen::Ref<const PointRows<Dim>>& points,
                                Eigen::Matrix<double, Dim, 1>& centre, double& radius,
                                bool fix_radius, DistanceSolver solver = DistanceSolver::built);

}  // namespace rotacal
