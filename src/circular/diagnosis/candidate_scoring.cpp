// SPDX-License-Identifier: BSD-3-Clause
// The scoring of the circular-test diagnosis: visibility at plausible sizes, F-test and BIC
// of an entry against the current model (the engine's score_columns), one by one or from a pool
// of every variant.
#include "../../diagnose/scoring.hpp"
#include "diagnosis_detail.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal::circular_detail {

// Nonlinear parameters of an entry (they are profiled, not in the linear model).
int nonlinear_params(const CircularEffect& e) {
  if (e.kind == CircularEffectKind::backlash) return 1;
  if (e.kind == CircularEffectKind::reversal_spike) return 2;
  return 0;
}

// Visibility, F and BIC of entry e against a model whose whitened residuals r_w leave rss0,
// from the entry's Gram quantities (k <= 2 columns, per unit parameter): G = perp' perp and
// g = perp' r_w, perp its whitened columns with the model projected out, and Graw = Jw' Jw
// without. Scaled to plausible sizes (magnitude()), they are scored as the diagnosis engine
// scores its candidates (score_columns), the profiled nonlinear parameters counted.
Scored score_gram(const CircularEffect& e, const Eigen::MatrixXd& G, const Eigen::VectorXd& g,
                  const Eigen::MatrixXd& Graw, double rss0, double n, int num_free,
                  double min_chi2) {
  const auto units = e.param_units();
  Eigen::VectorXd m(G.cols());
  for (Eigen::Index j = 0; j < G.cols(); ++j) m[j] = magnitude(units[static_cast<std::size_t>(j)]);
  diagnosis_detail::CandidateGrams grams;
  grams.raw = m.asDiagonal() * Graw * m.asDiagonal();
  grams.perp = m.asDiagonal() * G * m.asDiagonal();
  grams.perp_r = m.cwiseProduct(g);
  grams.rr = rss0;
  grams.n = n;
  const diagnosis_detail::ColumnScore cs =
      diagnosis_detail::score_columns(m, grams, num_free, nonlinear_params(e), min_chi2);
  if (!cs.decided)  // not with finite columns
    throw DegenerateGeometry("circular diagnosis: the Gram matrix of " + e.id() +
                             " has no eigen decomposition");
  Scored s;
  s.effect = e;
  s.visible = cs.visible;
  s.absorbed = cs.absorbed;
  if (!cs.visible) return s;
  s.k = cs.k;
  if (e.kind == CircularEffectKind::reversal_spike) s.physical = cs.params[0] > 0.0;
  s.rss1 = cs.rss1;
  s.delta_bic = cs.delta_bic;
  s.p = cs.f_pvalue;
  return s;
}

// score_gram of entry e (whitened columns Jw) against the model spanned by Q.
Scored score_one(const CircularEffect& e, const Eigen::MatrixXd& Jw, const ModelBasis& Q,
                 const Eigen::VectorXd& r_w, int num_free, double min_chi2) {
  const Eigen::MatrixXd perp = Q.project_out(Jw);
  return score_gram(e, perp.transpose() * perp, perp.transpose() * r_w, Jw.transpose() * Jw,
                    r_w.squaredNorm(), static_cast<double>(r_w.size()), num_free, min_chi2);
}

// The candidates of a forward selection with the noise taken as white (whitening = a scale
// s), where a round's model grows by one entry. Per variant only k x k and e x k numbers are
// kept, no column: the model's effect columns enter an orthonormal basis q one entry at a time
// (baseline projected out, Gram-Schmidt twice against q, a remainder below 1e-9 of the column
// dropped as in ModelBasis), each variant keeps c = q' s J, and since r_w and q are orthogonal to
// the baseline, perp' perp = gb - c' c and perp' r_w = s J' r_w - c' (q' r_w), with
// gb = (P s J)' (P s J) and P the baseline's projector. A round costs O(n k) per variant
// instead of a projection on the whole model.
ScoringPool::ScoringPool(const Rows& R, const Whitening& W, const Eigen::MatrixXd& B,
                         const std::vector<const Eigen::MatrixXd*>& variants)
    : R_(&R), W_(&W), scale_(W.scale), variants_(variants) {
  ROTACAL_ASSERT(!W.w);
  qb_ = W.baseline(R, B).qb;
  for (const Eigen::MatrixXd& q : qb_) rank_ += static_cast<int>(q.cols());
  q_.resize(static_cast<Eigen::Index>(R.n), 0);
  for (const Eigen::MatrixXd* J : variants) {
    Eigen::MatrixXd jb = scale_ * *J;
    graw_.push_back(jb.transpose() * jb);
    remove_baseline(qb_, R.run_first, R.run_count, jb);
    gb_.push_back(jb.transpose() * jb);
    c_.emplace_back(0, jb.cols());
  }
}

void ScoringPool::add_to_model(const Eigen::MatrixXd& J) {
  Eigen::MatrixXd E = (*W_)(J);
  const Eigen::VectorXd norms = E.colwise().norm().transpose();
  remove_baseline(qb_, R_->run_first, R_->run_count, E);
  drop_absorbed(E, norms);
  for (Eigen::Index j = 0; j < E.cols(); ++j) {
    Eigen::VectorXd v = E.col(j);
    for (int pass = 0; pass < 2; ++pass)
      if (q_.cols() > 0) v -= q_ * (q_.transpose() * v);
    if (!(norms[j] > 0.0) || !(v.norm() > 1e-9 * norms[j])) continue;
    v.normalize();
    q_.conservativeResize(Eigen::NoChange, q_.cols() + 1);
    q_.col(q_.cols() - 1) = v;
    ++rank_;
    for (std::size_t i = 0; i < variants_.size(); ++i) {
      c_[i].conservativeResize(c_[i].rows() + 1, Eigen::NoChange);
      c_[i].row(c_[i].rows() - 1) = scale_ * (v.transpose() * *variants_[i]);
    }
  }
}

Scored ScoringPool::score(std::size_t i, const CircularEffect& e, const Eigen::VectorXd& r_w,
                          double min_chi2) const {
  const Eigen::VectorXd qr = q_.transpose() * r_w;
  const Eigen::MatrixXd G = gb_[i] - c_[i].transpose() * c_[i];
  const Eigen::VectorXd g = scale_ * (variants_[i]->transpose() * r_w) - c_[i].transpose() * qr;
  return score_gram(e, G, g, graw_[i], r_w.squaredNorm(), static_cast<double>(r_w.size()), rank_,
                    min_chi2);
}

}  // namespace rotacal::circular_detail
