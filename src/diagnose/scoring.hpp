// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/diagnose and its adapters: the linear algebra, scoring and cross-validation the
// search loop (diagnosis.cpp) uses, shared with the residual-structure and ambiguity files and
// the circular-test diagnosis (src/circular/diagnosis/).

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "rotacal/core/noise_model.hpp"
#include "rotacal/diagnose/diagnosis.hpp"

namespace rotacal::diagnosis_detail {

double rss(const Eigen::VectorXd& r);
/// RMS in um of residuals in mm.
double rms_um(const Eigen::VectorXd& r);
/// Plausible magnitudes of a candidate's parameters (for observability and scaling).
Eigen::VectorXd magnitudes(const Effect& c);
/// Least squares y ~ X d, rank-revealing (directions the rows cannot see get no weight).
Eigen::VectorXd solve_ls(const Eigen::MatrixXd& X, const Eigen::VectorXd& y);
/// Orthonormal basis of span(J), rank-revealing. J is taken by value and factorised in place:
/// pass a temporary (or std::move) to spare the n x p copy.
Eigen::MatrixXd orthonormal_basis(Eigen::MatrixXd J);
/// The same span by CholeskyQR2 (~2 n p^2 flops against ~4 n p^2 for the Householder QR and
/// its Q; the per-candidate bases of the coloured search were a quarter of a diagnosis at
/// rho 0.5), one pass where the normalised columns are well conditioned (Q^T Q = I to ~1e-12),
/// falling back to orthonormal_basis where J is near rank-deficient.
Eigen::MatrixXd orthonormal_basis_full_rank(const Eigen::MatrixXd& J);
/// Columns of C with their component in span(Q) removed (Q orthonormal).
Eigen::MatrixXd project_out(const Eigen::MatrixXd& Q, const Eigen::MatrixXd& C);
/// What the columns of Q (orthonormal) extended by Jc leave of r: r - Jp b with Jp = Jc - Q A,
/// A = Q^T Jc, the least-squares b from k x k products (Jp^T Jp = Jc^T Jc - A^T A,
/// Jp^T r = Jc^T r - A^T Qr; Qr = Q^T r, given once per round): about half the work of
/// orthonormalising Jp, which each candidate's noise model needs. Empty where a column of Jc
/// keeps under 1e-5 of its norm outside span(Q), or Jp is near rank-deficient: there the
/// subtraction loses the digits that decide, and the caller orthonormalises Jp instead.
Eigen::VectorXd residual_without(const Eigen::MatrixXd& Q, const Eigen::VectorXd& r,
                                 const Eigen::VectorXd& Qr, const Eigen::MatrixXd& Jc);
/// Free (non-zero) columns of a fit's Jacobian.
Eigen::MatrixXd free_columns(const Eigen::MatrixXd& J);

// ---- What a candidate's columns add to a linear model, defined once for this engine and the
// circular-test diagnosis (src/circular/diagnosis/, an adapter at this layer). Each caller forms
// the Gram quantities its own way (from columns, from products, from a pool of variants, under
// its noise model); what they mean is decided here.

/// A candidate's k columns per plausible size (column j scaled by the plausible magnitude m_j of
/// its parameter) and whitened, so that squared norms are chi-square changes.
struct CandidateGrams {
  Eigen::MatrixXd raw;     ///< k x k Gram matrix of the columns
  Eigen::MatrixXd perp;    ///< k x k Gram matrix once the model's columns are projected out
  Eigen::VectorXd perp_r;  ///< k, the projected columns' products with the whitened residuals
  double rr = 0.0;         ///< the whitened residuals' squared norm (rss before the refit)
  double n = 0.0;          ///< readings
};

/// The candidate against the model.
struct ColumnScore {
  /// False where the eigen decomposition failed, or an eigenvalue lies within `tol` of the
  /// threshold (a caller working from rounded products then decides from the columns).
  bool decided = true;
  /// Some direction changes chi-square by >= min_chi2 at plausible sizes once the model is
  /// projected out.
  bool visible = false;
  /// Not visible, but a direction of the columns alone is: the model absorbs the candidate.
  bool absorbed = false;
  int k = 0;               ///< visible directions
  Eigen::MatrixXd V;       ///< them, per plausible size (orthonormal columns)
  Eigen::VectorXd d;       ///< the refit's coefficient along each
  Eigen::VectorXd params;  ///< the refit's parameters, m .* (V d), in the candidate's units
  double rss1 = 0.0;       ///< whitened residual sum of squares after the refit
  double delta_bic = 0.0;  ///< n log(rss1 / rss0) + (k + nonlinear) log n
  double f_pvalue = 1.0;   ///< P(F > f) of the rss drop, F(k, n - num_free - k - nonlinear)
};

/// Score candidate columns whose plausible magnitudes are m against a model of num_free free
/// linear parameters. The eigenvalues of g.perp are the chi-square changes of unit directions
/// per plausible size; those of at least min_chi2 are visible. Along the visible directions
/// A = perp_columns V (orthogonal columns of squared norms lambda) the refit removes
/// (V' perp_r)^2 / lambda each. `nonlinear`: the candidate's parameters profiled outside the
/// linear model (a backlash's delay), counted in the BIC penalty (Schwarz 1978: k log n) and the
/// F-test's degrees of freedom. The tests hold with the full n since the residuals are whitened
/// (GLS). tol > 0: undecided where an eigenvalue lies within tol of min_chi2.
ColumnScore score_columns(const Eigen::VectorXd& m, const CandidateGrams& g, int num_free,
                          int nonlinear, double min_chi2, double tol = 0.0);

/// The block (0 .. blocks - 1) of reading i of `size` readings in time order cut into `blocks`
/// contiguous blocks, shifted by `shift` (mod blocks): the fold of a blocked cross-validation.
inline int contiguous_block(std::size_t i, std::size_t size, int blocks, int shift = 0) {
  return (static_cast<int>(i * static_cast<std::size_t>(blocks) / size) + shift) % blocks;
}

/// The model's coefficients from the training rows of a fold (indices into X's rows, ascending).
using FoldFit = std::function<Eigen::VectorXd(const std::vector<Eigen::Index>& train)>;

/// Blocked cross-validated RMS (um) of predicting y (mm) from the columns X: for each fold
/// k < K, the coefficients `fit` finds on the rows of the other folds predict the rows of fold k
/// (folds without test or training rows are skipped; 0 where no row is predicted).
double blocked_cv_rms_um(const Eigen::MatrixXd& X, const Eigen::VectorXd& y,
                         const std::vector<int>& fold, int K, const FoldFit& fit);

/// Blocked K-fold assignment: each group's readings in time order, cut into K contiguous blocks,
/// fewer (at least 2) where the noise model's correlation time makes blocks of a K-th too short.
std::vector<int> cv_folds(const DiagnosisProblem& P, int K, const NoiseModel* noise = nullptr);
/// Cross-validated RMS (um) of predicting r from columns X (blocked_cv_rms_um, each fold's
/// linearised refit by solve_ls on the rest).
double cv_rms_um(const Eigen::MatrixXd& X, const Eigen::VectorXd& r, const std::vector<int>& fold,
                 int K);

/// One candidate scored against the current model by a linearised refit, in whitened units
/// (residuals and columns multiplied by the noise model's W: unit variance, independent); the
/// numbers are score_columns'.
struct Score {
  Effect effect;
  bool observable = false;
  std::string why_not;
  int k = 0;                   ///< observable directions
  Eigen::MatrixXd A;           ///< whitened candidate columns along them, model projected out
  Eigen::MatrixXd directions;  ///< the candidate's parameters (its units) per observable direction
  Eigen::MatrixXd X;           ///< [J, Jc * directions] in mm, for cross-validation (set by the
                               ///< search, only for a candidate that can pass)
  Eigen::VectorXd signature;   ///< fitted change of the whitened residuals
  Eigen::VectorXd params;      ///< the candidate's fitted parameters (its units)
  double rss1 = 0.0;           ///< whitened residual sum of squares after the refit
  double delta_bic = 0.0;
  double f_pvalue = 1.0;
};

/// What every candidate of a round is scored against.
struct ScoringInputs {
  Eigen::VectorXd r_w;    ///< whitened residuals of the current model
  Eigen::MatrixXd Jfree;  ///< its free Jacobian columns, mm per unit
  Eigen::MatrixXd Q_w;    ///< orthonormal basis of the whitened free columns
  int num_free = 0;
};

/// Why a candidate whose Jacobian is not finite on the readings is not scored.
inline constexpr const char* kUndefinedOnReadings =
    "its effect on these readings is undefined (its derivatives are not finite: the readings do "
    "not span what it depends on)";

/// Score candidate `c` (Jc_w: its whitened Jacobian, mm per unit, taken by value and worked on
/// in place); directions whose plausible sizes change chi-square by less than min_chi2 are not
/// visible. The columns A and the signature are kept only if delta BIC < columns_below_delta_bic
/// (only a candidate that can pass needs them).
Score score(const ScoringInputs& in, const Effect& c, Eigen::MatrixXd Jc_w, double min_chi2,
            double columns_below_delta_bic = std::numeric_limits<double>::infinity());
/// The inner products score() works from, in the noise model's metric <x, y> = x^T V^-1 y:
/// f the current model's free columns, c the candidate's (mm per unit), r the residuals.
struct CandidateProducts {
  Eigen::MatrixXd G_ff, g_fc, G_cc;
  Eigen::VectorXd g_fr, g_cr;
  double rr = 0.0;     ///< <r, r>
  Eigen::Index n = 0;  ///< readings
};
/// The current model's free columns Jf as any white or AR(1) noise model of the given streams
/// sees them (each candidate of a coloured round has its own): lag products per stream, and
/// the plain Gram matrix. O(n p^2) once a round.
struct ModelProducts {
  StreamLagProducts lags;
  Eigen::MatrixXd gram;
  ModelProducts(const Eigen::MatrixXd& Jf, std::vector<std::vector<Eigen::Index>> streams);
};
/// The products for candidate columns Jc and residuals r (mm) under whitener W (AR order <= 1,
/// no random walk), or white noise of sigma_mm where W is null. O(n p k).
CandidateProducts candidate_products(const ArWhitener* W, double sigma_mm,
                                     const ModelProducts& model, const Eigen::MatrixXd& Jf,
                                     const Eigen::MatrixXd& Jc, const Eigen::VectorXd& r);
/// score() from inner products alone: O(p^3) per candidate where score() needs a basis of the
/// whitened model columns, O(n p^2), for each candidate's own noise model (most of the
/// coloured search's cost at rho 0.5). Returns what the round's table needs (observability,
/// parameters, rss1, delta BIC, F-test) without the columns A, X and signature, which only a
/// candidate able to pass needs. Empty where the products cannot decide as the columns would:
/// the model's columns near rank-deficient, or a chi-square change within rounding of min_chi2.
std::optional<Score> score_from_products(const CandidateProducts& g, const Effect& c, int num_free,
                                         double min_chi2);
/// Cosine of the angle between two signatures (0 if either is zero).
double correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

/// Where the predictions of two ambiguous candidates differ most, in words (ambiguity.cpp);
/// differences below sigma_mm are "less than the noise".
std::string separating_test(const DiagnosisProblem& P, const ModelFit& fit, const Score& a,
                            const Score& b, double sigma_mm);
/// The strongest remaining structure, in words (residual_structure.cpp).
std::string describe_structure(const std::vector<GroupResidual>& groups);

}  // namespace rotacal::diagnosis_detail

namespace rotacal::diagnosis_detail {

/// Where in a group the residual is largest: the group's swept rotary axis (0: none, then the
/// range is in time), and the contiguous range of 12 equal bins around the bin of largest
/// |mean residual| whose |mean| is at least half of it (deg, or s).
struct Location {
  char axis = 0;
  double from = 0.0, to = 0.0;
  double peak_um = 0.0;  ///< the largest bin mean, um
};
Location locate(const DiagnosisProblem& P, const Eigen::VectorXd& r, const std::string& group);

/// Test of structure left in the residuals against the noise model (residual_structure.cpp):
/// per group, a smooth function of its swept angle (the harmonics its sampling resolves over
/// a full turn; polynomials of degree 1..4 on an arc, or in time when no angle moves),
/// whitened, the model's columns projected out, F-tested on the whitened residuals.
struct StructureTest {
  double p_value = 1.0;  ///< Bonferroni-corrected over the groups
  std::string group;     ///< the group with the smallest p-value
};
using Whiten = std::function<Eigen::MatrixXd(const Eigen::MatrixXd&)>;
/// `whitener_for(group, G)`: the whitening to test group's columns G with. r_mm: residuals
/// of the model whose free columns are Jfree.
StructureTest structure_test(
    const DiagnosisProblem& P, const Eigen::VectorXd& r_mm, const Eigen::MatrixXd& Jfree,
    int num_free,
    const std::function<Whiten(const std::string&, const Eigen::MatrixXd&)>& whitener_for);

}  // namespace rotacal::diagnosis_detail
