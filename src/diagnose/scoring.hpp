#pragma once
// Internal to src/diagnose: the linear algebra, scoring and cross-validation the search loop
// (diagnosis.cpp) uses, shared with the residual-structure and ambiguity files.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rotacal/diagnose/diagnosis.hpp"

namespace rotacal::diagnosis_detail {

double rss(const Eigen::VectorXd& r);
/// RMS in um of residuals in mm.
double rms_um(const Eigen::VectorXd& r);
/// Plausible magnitudes of a candidate's parameters (for observability and scaling).
Eigen::VectorXd magnitudes(const Effect& c);
/// Least squares y ~ X d, rank-revealing (directions the rows cannot see get no weight).
Eigen::VectorXd solve_ls(const Eigen::MatrixXd& X, const Eigen::VectorXd& y);
/// Orthonormal basis of span(J), rank-revealing.
Eigen::MatrixXd orthonormal_basis(const Eigen::MatrixXd& J);
/// Columns of C with their component in span(Q) removed (Q orthonormal).
Eigen::MatrixXd project_out(const Eigen::MatrixXd& Q, const Eigen::MatrixXd& C);
/// Free (non-zero) columns of a fit's Jacobian.
Eigen::MatrixXd free_columns(const Eigen::MatrixXd& J);
/// Blocked K-fold assignment: each group's readings in time order, cut into K contiguous blocks.
std::vector<int> cv_folds(const DiagnosisProblem& P, int K);
/// Cross-validated RMS (um) of predicting r from columns X (linearised refit on the rest).
double cv_rms_um(const Eigen::MatrixXd& X, const Eigen::VectorXd& r, const std::vector<int>& fold,
                 int K);

/// One candidate scored against the current model by a linearised refit.
struct Score {
  Effect effect;
  bool observable = false;
  std::string why_not;
  int k = 0;                   // observable directions
  Eigen::MatrixXd A;           // observable part of the candidate's columns, J projected out
  Eigen::MatrixXd X;           // [J, candidate columns] for cross-validation
  Eigen::VectorXd signature;   // fitted change of the model, mm
  double rss1 = 0.0;
  double delta_bic = 0.0;
  double f_pvalue = 1.0;
};

/// Score candidate `c` against `fit` (Jfree: its free Jacobian columns, Q: their orthonormal
/// basis) at noise sigma_mm; directions whose plausible sizes change chi-square by less than
/// min_chi2 are not visible.
Score score(const DiagnosisProblem& P, const ModelFit& fit, const Eigen::MatrixXd& Jfree,
            const Eigen::MatrixXd& Q, const Effect& c, double sigma_mm, double min_chi2);
/// Cosine of the angle between two signatures (0 if either is zero).
double correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

/// Where the predictions of two ambiguous candidates differ most, in words (ambiguity.cpp).
std::string separating_test(const DiagnosisProblem& P, const ModelFit& fit, const Score& a,
                            const Score& b, double sigma_mm);
/// The strongest remaining structure, in words (residual_structure.cpp).
std::string describe_structure(const std::vector<GroupResidual>& groups);

}  // namespace rotacal::diagnosis_detail
