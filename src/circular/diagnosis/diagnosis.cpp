// SPDX-License-Identifier: BSD-3-Clause
// Diagnosis of ballbar circular tests (diagnosis.hpp): the search. Its catalogue, columns, fits,
// scoring and cross-validation are the other files of this folder (diagnosis_detail.hpp); here
// the forward selection with the thresholds of the rotary diagnosis, and the backward
// elimination under the noise model.
#include "rotacal/circular/diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "diagnosis_detail.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/stats.hpp"

namespace rotacal {

namespace circular_detail {

namespace {

const CircularDiagnosisOptions& checked(const CircularDiagnosisOptions& o) {
  if (!(o.alpha > 0.0 && o.alpha < 1.0))
    throw InvalidArgument("diagnose_circular: alpha must be in (0, 1), got " +
                          std::to_string(o.alpha));
  if (!o.screw_pitch.allFinite() || !(o.screw_pitch.array() > 0.0).all())
    throw InvalidArgument("diagnose_circular: screw_pitch must be positive (X, Y, Z), mm");
  if (o.max_findings < 0) throw InvalidArgument("diagnose_circular: max_findings must be >= 0");
  if (o.cv_blocks < 2) throw InvalidArgument("diagnose_circular: cv_blocks must be >= 2");
  if (!(o.min_visible_chi2 > 0.0 && std::isfinite(o.min_visible_chi2)))
    throw InvalidArgument("diagnose_circular: min_visible_chi2 must be positive and finite, got " +
                          std::to_string(o.min_visible_chi2));
  return o;
}

std::vector<CircularEffect> catalogue_of(const CircularDiagnosisOptions& o) {
  std::vector<CircularEffect> catalogue;
  if (o.only.empty()) {
    catalogue = circular_catalogue();
  } else {
    for (const std::string& id : o.only) catalogue.push_back(CircularEffect::parse(id));
  }
  return catalogue;
}

}  // namespace

CircularSearch::CircularSearch(const BallbarSession& session, const CircularDiagnosisOptions& o)
    : o_(checked(o)),
      catalogue_(catalogue_of(o)),
      R(gather(session, circular_runs(session))),
      B(baseline_columns(R)) {
  out.n = R.n;

  // Entries these runs cannot see at all; the axes' own scales, never.
  for (const CircularEffect& e : catalogue_) {
    const std::string why = not_moved(R, e);
    if (why.empty())
      cands.push_back(e);
    else
      out.unobservable.push_back({e.id(), why});
  }
  for (int a = 0; a < 3; ++a)
    out.unobservable.push_back(
        {"scale_" + axis_name(a),
         "a circle sees only the difference of its two axes' scales (scale_mismatch_*); their "
         "common "
         "part changes the radius, which cannot be told from the bar length's calibration"});

  for (const CircularEffect& e : cands) {
    if (e.kind == CircularEffectKind::reversal_spike) {
      for (double tau : kSpikeTauGrid)
        for (double delay : kDelayGrid)
          cols[e.id()].push_back({tau, delay, effect_columns(R, e, o_.screw_pitch, tau, delay)});
    } else if (e.kind == CircularEffectKind::backlash) {
      for (double delay : kDelayGrid)
        cols[e.id()].push_back({0.0, delay, effect_columns(R, e, o_.screw_pitch, 0.0, delay)});
    } else {
      cols[e.id()].push_back({0.0, 0.0, effect_columns(R, e, o_.screw_pitch)});
    }
  }

  fit = gls(R, B, R.y, W);  // ordinary least squares first
  out.baseline_rms_um = rms_um(fit.r_mm);
  for (const CircularEffect& e : cands)
    for (const auto& v : cols[e.id()]) variant_columns.push_back(&v.J);
}

void CircularSearch::refit_noise() {
  if (!o_.model_noise) return;
  NoiseModel nm = noise_of(R, fit.r_mm);
  W.set(nm);
  fit = gls(R, model_columns(R, B, chosen, o_.screw_pitch), R.y, W);
}

bool CircularSearch::is_chosen(const std::string& id) const {
  return std::any_of(chosen.begin(), chosen.end(),
                     [&](const Chosen& c) { return c.effect.id() == id; });
}

// Every candidate not chosen yet, at its best variant, against the current model: through the
// pool (white noise) or by projecting on Q (AR); sorted by delta BIC. Records which ids the
// model absorbs and which are invisible.
std::vector<Scored> CircularSearch::score_round(const ScoringPool* pool, const ModelBasis* Q) {
  const auto score_variant = [&](std::size_t i, const CircularEffect& e) {
    return Q ? score_one(e, W(*variant_columns[i]), *Q, fit.r_w, Q->rank(), o_.min_visible_chi2)
             : pool->score(i, e, fit.r_w, o_.min_visible_chi2);
  };
  std::vector<Scored> scores;
  absorbed.clear();
  invisible.clear();
  std::size_t variant_index = 0;
  for (const CircularEffect& e : cands) {
    const auto& cs = cols[e.id()];
    const std::size_t first_variant = variant_index;
    variant_index += cs.size();
    if (is_chosen(e.id())) continue;
    Scored best;
    bool have = false;
    for (std::size_t g = 0; g < cs.size(); ++g) {
      Scored sc = score_variant(first_variant + g, e);
      sc.tau = cs[g].tau;
      sc.delay = cs[g].delay;
      if (!have || (sc.visible && (!best.visible || sc.rss1 < best.rss1))) best = sc, have = true;
    }
    if (!best.visible) {
      (best.absorbed ? absorbed : invisible).insert(e.id());
      continue;
    }
    scores.push_back(best);
  }
  std::sort(scores.begin(), scores.end(),
            [](const Scored& x, const Scored& y) { return x.delta_bic < y.delta_bic; });
  return scores;
}

// Forward selection; under white noise (a whitening that stays for every round) through a
// ScoringPool, under the AR model (`ar`: re-estimated every round) by projecting each variant.
void CircularSearch::forward(bool ar, int limit, bool record) {
  std::unique_ptr<ScoringPool> pool;
  for (int round = 0;; ++round) {
    if (ar) refit_noise();
    std::unique_ptr<ModelBasis> Q;
    if (W.w) {
      Q = std::make_unique<ModelBasis>(R, W(model_columns(R, B, chosen, o_.screw_pitch)));
    } else if (!pool) {
      pool = std::make_unique<ScoringPool>(R, W, B, variant_columns);
      for (const Chosen& c : chosen)
        pool->add_to_model(effect_columns(R, c.effect, o_.screw_pitch, c.tau, c.delay));
    }
    const std::vector<Scored> scores = score_round(pool.get(), Q.get());
    if (record && round == 0)
      for (const Scored& sc : scores)
        out.first_round.push_back({sc.effect.id(), sc.k, sc.delta_bic, sc.p,
                                   std::sqrt(sc.rss1 / static_cast<double>(R.n))});
    if (static_cast<int>(chosen.size()) >= limit) return;
    const double m = static_cast<double>(std::max<std::size_t>(scores.size(), 1));
    const Scored* pick = nullptr;
    for (const Scored& sc : scores)
      if (sc.p * m < o_.alpha && sc.delta_bic < o_.min_delta_bic && sc.physical) {
        pick = &sc;
        break;
      }
    if (!pick) return;
    chosen.push_back({pick->effect, pick->tau, pick->delay});
    fit = gls(R, model_columns(R, B, chosen, o_.screw_pitch), R.y, W);
    if (pool)
      pool->add_to_model(effect_columns(R, pick->effect, o_.screw_pitch, pick->tau, pick->delay));
  }
}

// Backward elimination under the current noise model: drop the entry whose drop-one test
// fails worst (Bonferroni over the catalogue; a spike that does not stick outward fails),
// refit and re-estimate the noise, until every entry left passes.
void CircularSearch::eliminate() {
  const double m = static_cast<double>(std::max<std::size_t>(cands.size(), 1));
  while (!chosen.empty()) {
    const double n = static_cast<double>(R.n);
    std::vector<Eigen::Index> offs;
    const Eigen::MatrixXd Mk = model_columns(R, B, chosen, o_.screw_pitch, &offs);
    std::size_t worst = chosen.size();
    double worst_score = -1.0;
    // Every drop-one refit from one QR of the whitened model (CompressedFit).
    const CompressedFit drop(R, W(Mk), W(Eigen::MatrixXd(R.y)).col(0));
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      const Eigen::Index width = (k + 1 < chosen.size() ? offs[k + 1] : Mk.cols()) - offs[k];
      const double rss_without = drop.rss_without(offs[k], width);
      const int kk = static_cast<int>(width) + nonlinear_params(chosen[k].effect);
      const double dof = n - static_cast<double>(Mk.cols()) - 1.0;
      const double F = ((rss_without - fit.rss_w) / kk) / (fit.rss_w / dof);
      const double p = stats::f_sf(std::max(F, 0.0), kk, dof);
      const double dbic =
          n * std::log(std::max(fit.rss_w, 1e-300) / rss_without) + kk * std::log(n);
      const bool outward =
          chosen[k].effect.kind != CircularEffectKind::reversal_spike || fit.beta[offs[k]] > 0.0;
      const double score = (p * m < o_.alpha && dbic < o_.min_delta_bic && outward)
                               ? -1.0
                               : p + (dbic >= o_.min_delta_bic ? 1.0 : 0.0) + (outward ? 0.0 : 2.0);
      if (score > worst_score) worst_score = score, worst = k;
    }
    if (worst_score < 0.0) break;
    chosen.erase(chosen.begin() + static_cast<std::ptrdiff_t>(worst));
    fit = gls(R, model_columns(R, B, chosen, o_.screw_pitch), R.y, W);
    refit_noise();
  }
}

CircularDiagnosis CircularSearch::run() {
  // 1. Forward with the noise taken as white, sigma from successive differences: the residuals
  //    of the baseline hold the large signatures, and an AR model fitted to them would take
  //    those for noise and whiten them away. White-noise tests are too lenient on coloured
  //    noise; step 2 corrects that.
  {
    const double sd = difference_sigma(R, fit.r_mm);
    W.set_scale(sd > 0.0 ? 1.0 / sd : 1.0);
    fit = gls(R, B, R.y, W);
  }
  forward(false, o_.max_findings + 6, true);
  if (o_.model_noise) {
    // 2. Noise modelled from what the model leaves; backward elimination of every entry whose
    //    drop-one test fails under it (Bonferroni over the catalogue), the noise re-estimated
    //    after each removal.
    refit_noise();
    eliminate();
    // 3. Forward again under the AR model, re-estimated every round.
    forward(true, o_.max_findings, false);
  }

  refine();

  // What the refinement moved may no longer pass (or a spike may no longer stick outward).
  if (o_.model_noise) {
    fit = gls(R, model_columns(R, B, chosen, o_.screw_pitch), R.y, W);
    refit_noise();
    eliminate();
  }

  final_model();
  add_findings();
  explain_unobservable();
  return out;
}

}  // namespace circular_detail

CircularDiagnosis diagnose_circular(const BallbarSession& session,
                                    const CircularDiagnosisOptions& o) {
  return circular_detail::CircularSearch(session, o).run();
}

}  // namespace rotacal
