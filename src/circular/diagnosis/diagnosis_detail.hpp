// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/circular: the parts of the circular-test diagnosis (diagnosis.hpp) and the
// search that puts them together. catalogue.cpp: the entries, their parameters and causes;
// columns.cpp: the readings as rows and each entry's columns; fit.cpp: whitening and the
// block least squares over the runs' baselines (GLS); candidate_scoring.cpp: visibility, F and
// BIC of an entry against the model; cross_validation.cpp: the blocked CV RMS; diagnosis.cpp,
// diagnosis_refine.cpp, diagnosis_findings.cpp: the selection, the nonlinear parameters and
// the final model with its findings.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "rotacal/circular/diagnosis.hpp"
#include "rotacal/core/angles.hpp"
#include "rotacal/core/noise_model.hpp"

namespace rotacal::circular_detail {

std::string axis_name(int i);

// Plausible sizes per unit, for visibility (see CircularDiagnosisOptions::min_visible_chi2).
double magnitude(const std::string& unit);

// ----------------------------------------------------------------------------- columns

struct Rows {
  std::size_t n = 0;
  Eigen::VectorXd y;  // reading - L0, mm
  std::vector<std::string> group;
  std::vector<double> time;
  std::vector<int> run;
  std::vector<CircularPlane> plane;
  std::vector<std::array<int, 2>> axes_uv;  // plane_axes of each row's plane
  std::vector<double> theta, omega;
  std::vector<double> cos_theta, sin_theta;  // of theta, computed once: every column uses them
  std::vector<Eigen::Vector3d> axes;         // commanded machine axes, mm
  // Rows of run k: [run_first[k], run_first[k] + run_count[k]) (gather appends runs in order).
  std::vector<Eigen::Index> run_first, run_count;
  Eigen::Vector3d centre_axes = Eigen::Vector3d::Zero();
  double radius = 0.0;
  std::set<CircularPlane> planes;
  std::set<int> moving_axes;
  std::set<CircularDirection> directions;
  std::size_t runs = 0;
};

Rows gather(const BallbarSession& s, const std::vector<CircularRunData>& runs);

Eigen::MatrixXd baseline_columns(const Rows& R);

// d reading / d parameter (mm per parameter unit) of an entry's linear parameters; backlash and
// spikes with the axis reversing `delay` (s) after the commanded reversal (its servo lag), a
// spike decaying with `tau` (s).
Eigen::MatrixXd effect_columns(const Rows& R, const CircularEffect& e, const Eigen::Vector3d& pitch,
                               double tau = 0.0, double delay = 0.0);

// Why an entry cannot be seen at all by these runs (empty: it can be, as far as its columns go).
std::string not_moved(const Rows& R, const CircularEffect& e);

// The model's columns for a list of chosen entries (spikes at their tau).
struct Chosen {
  CircularEffect effect;
  double tau = 0.0;                                    // spike
  double delay = 0.0;                                  // backlash, spike
  double delay_sd = 0.0;                               // its 1 sigma (after the scan)
  std::pair<double, double> delay_range = {0.0, 0.0};  // its delta-chi-square-1 range
};

Eigen::MatrixXd model_columns(const Rows& R, const Eigen::MatrixXd& B,
                              const std::vector<Chosen>& chosen, const Eigen::Vector3d& pitch,
                              std::vector<Eigen::Index>* offsets = nullptr);

// ----------------------------------------------------------------------------- fit

// Whitening of columns (mm) to unit-variance units: the AR whitener of a coloured noise model,
// or 1 / sigma of a white one, so that squared norms are chi-squares (visibility, F, BIC).
struct Whitening {
  std::unique_ptr<ArWhitener> w;
  double scale = 1.0;  // 1 / sigma (mm) when w is null
  Eigen::MatrixXd operator()(Eigen::MatrixXd M) const {
    if (w && M.cols() > 0)
      w->apply(M);
    else
      M *= scale;
    return M;
  }
  void set(const NoiseModel& nm) {
    w = nm.white() ? nullptr : std::make_unique<ArWhitener>(nm);
    scale = nm.white() && nm.sigma_um > 0.0 ? 1.0 / (nm.sigma_um * 1e-3) : 1.0;
    ++version;
  }
  /// White noise of sigma 1 / s (mm).
  void set_scale(double s) {
    w.reset();
    scale = s;
    ++version;
  }
  int version = 0;  ///< changes with the whitening (keys the baseline cache)
  /// The whitened baseline B_w and its per-run orthonormal bases under this whitening: B is the
  /// same in every fit, so they are computed once per whitening (baseline()).
  struct Baseline {
    int version = -1;
    Eigen::MatrixXd Bw;
    std::vector<Eigen::MatrixXd> qb;
  };
  const Baseline& baseline(const struct Rows& R, const Eigen::Ref<const Eigen::MatrixXd>& B) const;

 private:
  mutable Baseline baseline_;
};

// Zero the effect columns that the baseline absorbed (fit.cpp).
void drop_absorbed(Eigen::MatrixXd& E, const Eigen::VectorXd& norm_before);

// Per-run orthonormal bases of the baseline columns of (whitened) M, rows by `first`/`count`.
std::vector<Eigen::MatrixXd> baseline_bases(const std::vector<Eigen::Index>& first,
                                            const std::vector<Eigen::Index>& count,
                                            const Eigen::MatrixXd& M);

void remove_baseline(const std::vector<Eigen::MatrixXd>& qb, const std::vector<Eigen::Index>& first,
                     const std::vector<Eigen::Index>& count, Eigen::MatrixXd& X);

// Least-squares coefficients of y on [B | E] (both already whitened; qb: B's per-run bases),
// rows of run k at [first[k], first[k] + count[k]).
Eigen::VectorXd block_solve(const std::vector<Eigen::Index>& first,
                            const std::vector<Eigen::Index>& count, const Eigen::MatrixXd& B,
                            const std::vector<Eigen::MatrixXd>& qb, const Eigen::MatrixXd& E,
                            const Eigen::VectorXd& y);

// The same for M = [B | E] in one matrix.
Eigen::VectorXd block_solve(const std::vector<Eigen::Index>& first,
                            const std::vector<Eigen::Index>& count, const Eigen::MatrixXd& M,
                            const Eigen::VectorXd& y);

// Orthonormal basis of the span of whitened model columns [B | E], kept as the per-run bases
// of the baseline and one of the effect columns with the baseline projected out (orthogonal to
// them): projecting a column out costs O(n (3 + e)), not O(n (3 runs + e)).
class ModelBasis {
 public:
  ModelBasis(const Rows& R, const Eigen::MatrixXd& Mw);
  /// Dimension of the span.
  int rank() const;
  /// X less its projection on the span.
  Eigen::MatrixXd project_out(Eigen::MatrixXd X) const;

 private:
  const std::vector<Eigen::Index>* first_;
  const std::vector<Eigen::Index>* count_;
  std::vector<Eigen::MatrixXd> qb_;
  Eigen::MatrixXd qe_;
};

// Least-squares fits of y on the baseline and subsets of the effect columns, all from one QR:
// with P the whitened baseline projected out run by run, [P E_w | P y_w] = Q Rf, and the fit on
// effect columns S leaves |Rf_S x - rf_y|^2 minimised (Q has orthonormal columns), a problem of
// e + 1 rows instead of n.
class CompressedFit {
 public:
  CompressedFit(const Rows& R, const Eigen::MatrixXd& Mw, const Eigen::VectorXd& yw);
  /// Whitened residual sum of squares of the fit without the model columns [from, from + count)
  /// (indices into Mw; effect columns only).
  double rss_without(Eigen::Index from, Eigen::Index count) const;

 private:
  Eigen::Index nb_;
  Eigen::MatrixXd rf_;
};

// GLS fit of y on M under whitening W: whitened residual sum of squares and coefficients.
struct Gls {
  Eigen::VectorXd beta, r_mm, r_w;
  double rss_w = 0.0;
};
// M = [B | E], B the baseline (whitened once per whitening: Whitening::baseline).
Gls gls(const Rows& R, const Eigen::MatrixXd& M, const Eigen::VectorXd& y, const Whitening& W);

// Noise sigma (mm) from successive differences within each run (fit.cpp).
double difference_sigma(const Rows& R, const Eigen::VectorXd& r);
// The noise model of residuals r: AR, pooled over the runs.
NoiseModel noise_of(const Rows& R, const Eigen::VectorXd& r);

double rms_um(const Eigen::VectorXd& r);

// ----------------------------------------------------------------------------- scoring

inline const std::vector<double> kSpikeTauGrid = {0.003, 0.006, 0.012, 0.025, 0.05, 0.1, 0.2};
inline const std::vector<double> kDelayGrid = {0.0, 0.0005, 0.001, 0.002, 0.004, 0.008, 0.016};

// Nonlinear parameters of an entry (they are profiled, not in the linear model).
int nonlinear_params(const CircularEffect& e);

// A candidate scored against the current model.
struct Scored {
  CircularEffect effect;
  double tau = 0.0, delay = 0.0;
  int k = 0;  // visible directions
  double rss1 = 0.0, delta_bic = 0.0, p = 1.0;
  bool visible = false;
  bool absorbed = false;  // visible on its own, not once the model is projected out
  bool physical = true;   // a spike sticks outward: h > 0
};

// Visibility, F and BIC of entry e from its Gram quantities (candidate_scoring.cpp).
Scored score_gram(const CircularEffect& e, const Eigen::MatrixXd& G, const Eigen::VectorXd& g,
                  const Eigen::MatrixXd& Graw, double rss0, double n, int num_free,
                  double min_chi2);

// score_gram of entry e (whitened columns Jw) against the model spanned by Q.
Scored score_one(const CircularEffect& e, const Eigen::MatrixXd& Jw, const ModelBasis& Q,
                 const Eigen::VectorXd& r_w, int num_free, double min_chi2);

// The candidates of a forward selection with the noise taken as white: only k x k and e x k
// numbers per variant (candidate_scoring.cpp).
class ScoringPool {
 public:
  ScoringPool(const Rows& R, const Whitening& W, const Eigen::MatrixXd& B,
              const std::vector<const Eigen::MatrixXd*>& variants);
  /// Add a chosen entry's (unwhitened) columns to the model.
  void add_to_model(const Eigen::MatrixXd& J);
  /// Dimension of the model's span (baseline and chosen entries).
  int rank() const { return rank_; }
  /// Variant i of entry e against the model, whose whitened residuals are r_w.
  Scored score(std::size_t i, const CircularEffect& e, const Eigen::VectorXd& r_w,
               double min_chi2) const;

 private:
  const Rows* R_;
  const Whitening* W_;
  double scale_;
  std::vector<const Eigen::MatrixXd*> variants_;
  std::vector<Eigen::MatrixXd> qb_;
  Eigen::MatrixXd q_;
  int rank_ = 0;
  std::vector<Eigen::MatrixXd> c_, gb_, graw_;
};

// ----------------------------------------------------------------------------- cross-validation

// Blocked folds: each run's rows cut into K contiguous blocks.
std::vector<int> run_folds(const Rows& R, int K);

// Blocked cross-validated RMS (um) of predicting y from the columns M = [B | E].
double cv_rms_um(const Rows& R, const Eigen::MatrixXd& M, const Eigen::VectorXd& y,
                 const std::vector<int>& fold, int K);

// ----------------------------------------------------------------------------- the search

// The state of one diagnosis (diagnose_circular): rows, baseline, candidates with their
// columns, the chosen entries and the current fit under the current whitening.
class CircularSearch {
 public:
  /// Checks the options and the session (InvalidArgument, as diagnose_circular), gathers the
  /// rows and every candidate's columns, and fits the baseline.
  CircularSearch(const BallbarSession& session, const CircularDiagnosisOptions& o);
  CircularSearch(const CircularSearch&) = delete;  // holds pointers into its own members
  CircularSearch& operator=(const CircularSearch&) = delete;
  CircularDiagnosis run();

 private:
  // diagnosis.cpp: the selection.
  void refit_noise();
  bool is_chosen(const std::string& id) const;
  void forward(bool ar, int limit, bool record);
  std::vector<Scored> score_round(const ScoringPool* pool, const ModelBasis* Q);
  void eliminate();
  // diagnosis_refine.cpp: the nonlinear parameters (profiles).
  double rss_with(double* field, double value);
  std::function<double(double, double)> profile_of(std::size_t k);
  void scan_delay(std::size_t k, const std::function<double(double, double)>& f);
  void refine();
  // diagnosis_findings.cpp: the final model, its findings and what stays unobservable.
  void final_model();
  std::pair<double, bool> profile_std(double* field, double h, bool log_scale);
  Eigen::VectorXd beta_at(std::size_t k, double tau, double delay);
  void add_findings();
  void explain_unobservable();

  // Candidate columns, computed once: backlash over the delay grid, spikes over tau x delay.
  struct Variant {
    double tau = 0.0, delay = 0.0;
    Eigen::MatrixXd J;
  };
  const CircularDiagnosisOptions& o_;
  const std::vector<CircularEffect> catalogue_;  // before the rows: an unknown id is refused first
  const Rows R;
  const Eigen::MatrixXd B;
  CircularDiagnosis out;
  std::vector<CircularEffect> cands;
  std::map<std::string, std::vector<Variant>> cols;
  std::vector<const Eigen::MatrixXd*> variant_columns;  // every variant, in the order of cands
  std::vector<Chosen> chosen;
  Whitening W;
  Gls fit;
  std::set<std::string> absorbed;   // ids absorbed by the model at the last round
  std::set<std::string> invisible;  // ids too small to see at plausible sizes
  // The final model (final_model()): columns, degrees of freedom, the variance of unit weight
  // and the column-scaled inverse normal matrix.
  std::vector<Eigen::Index> offsets;
  Eigen::MatrixXd M;
  double final_dof = 0.0;
  double s2 = 0.0;
  Eigen::VectorXd col_scale;
  Eigen::MatrixXd Ninv;
};

}  // namespace rotacal::circular_detail
