// SPDX-License-Identifier: BSD-3-Clause
// ROTACAL_CERES_SOLVER (0 or 1) is defined for this file alone (CMakeLists.txt): the only file
// of the library that uses Ceres' solver rather than its header-only Jets.
#include "orthogonal_distance.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "rotacal/core/error.hpp"
#include "rotacal/core/joint_fit.hpp"

#if ROTACAL_CERES_SOLVER
#include <ceres/ceres.h>
#endif

namespace rotacal {

namespace {

// The residuals of all points for the joint-fit driver, x = (centre, radius), their Jacobian
// from the same functor through Jets.
template <int Dim>
class DistanceModel final : public ResidualModel {
 public:
  explicit DistanceModel(const Eigen::Ref<const PointRows<Dim>>& p) : p_(p) {}
  Eigen::Index num_residuals() const override { return p_.rows(); }
  int num_parameters() const override { return Dim + 1; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    evaluate_with_jets(
        [this](Eigen::Index i, const auto* xi, auto* out) {
          OrthogonalDistance<Dim>(p_.row(i).transpose())(xi, xi + Dim, out);
        },
        p_.rows(), 1, x, r, J);
  }

 private:
  const Eigen::Ref<const PointRows<Dim>>& p_;
};

template <int Dim>
bool refine_joint(const Eigen::Ref<const PointRows<Dim>>& p, Eigen::Matrix<double, Dim, 1>& centre,
                  double& radius, bool fix_radius) {
  const DistanceModel<Dim> model(p);
  std::vector<FitParameter> params;
  for (int k = 0; k < Dim; ++k) params.push_back({"centre " + std::string(1, "xyz"[k]), "mm"});
  params.push_back({"radius", "mm"});
  for (int k = 0; k < Dim; ++k) params[static_cast<std::size_t>(k)].start = centre[k];
  params.back().start = radius;
  params.back().held = fix_radius;
  JointFitSettings s;
  // The callers refuse collinear and coplanar points before: every parameter is determined,
  // none is to be fixed by the observability analysis.
  s.observability_min_chi2 = 0.0;
  // Ceres' solver stops at a relative change of the cost of 1e-15, i.e. at the minimum to
  // round-off; so does the driver here: it ends on a Jacobian evaluated at the solution, once no
  // step exceeds 1e-8 of a parameter's 1 sigma. That sigma is in units of the declared noise:
  // the start's RMS distance (the scatter), not below 1e-6 of the radius, so that the tolerance
  // stays far above round-off (~1e-16 of the radius) on exact points.
  s.stale_jacobian_sigma = 0.0;
  s.step_tolerance_sigma = 1e-8;
  Eigen::VectorXd x(Dim + 1), r(p.rows());
  x << centre, radius;
  model.evaluate(x, r, nullptr);
  s.sigma =
      std::max(std::sqrt(r.squaredNorm() / static_cast<double>(p.rows())), 1e-6 * std::abs(radius));
  const JointFitOutcome out = solve_joint(model, params, s);
  centre = out.values.template head<Dim>();
  radius = out.values[Dim];
  return out.summary.converged;
}

#if ROTACAL_CERES_SOLVER
template <int Dim>
bool refine_ceres(const Eigen::Ref<const PointRows<Dim>>& p, Eigen::Matrix<double, Dim, 1>& centre,
                  double& radius, bool fix_radius) {
  ceres::Problem problem;
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<OrthogonalDistance<Dim>, 1, Dim, 1>(
                                 new OrthogonalDistance<Dim>(p.row(i).transpose())),
                             nullptr, centre.data(), &radius);
  if (fix_radius) problem.SetParameterBlockConstant(&radius);
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.function_tolerance = 1e-15;
  so.parameter_tolerance = 1e-15;
  so.gradient_tolerance = 1e-15;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  return summary.termination_type == ceres::CONVERGENCE;
}
#endif

}  // namespace

bool ceres_solver_built() { return ROTACAL_CERES_SOLVER != 0; }

template <int Dim>
bool refine_orthogonal_distance(const Eigen::Ref<const PointRows<Dim>>& points,
                                Eigen::Matrix<double, Dim, 1>& centre, double& radius,
                                bool fix_radius, DistanceSolver solver) {
#if ROTACAL_CERES_SOLVER
  if (solver != DistanceSolver::joint) return refine_ceres<Dim>(points, centre, radius, fix_radius);
#else
  if (solver == DistanceSolver::ceres)
    throw InvalidArgument(
        "refine_orthogonal_distance: Ceres' solver was requested, but rotacal was built with "
        "-DROTACAL_CERES_SOLVER=OFF");
#endif
  return refine_joint<Dim>(points, centre, radius, fix_radius);
}

template bool refine_orthogonal_distance<2>(const Eigen::Ref<const PointRows<2>>&, Eigen::Vector2d&,
                                            double&, bool, DistanceSolver);
template bool refine_orthogonal_distance<3>(const Eigen::Ref<const PointRows<3>>&, Eigen::Vector3d&,
                                            double&, bool, DistanceSolver);

}  // namespace rotacal
