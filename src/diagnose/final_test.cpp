// SPDX-License-Identifier: BSD-3-Clause
// What the final model of a search leaves: its residual structure, the test for structure the
// noise does not explain (white: chi-square; coloured: per group against the other groups'
// noise model) and, where it is a function of one rotary angle, the per-angle table offered as
// the extension.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "rotacal/core/stats.hpp"
#include "search.hpp"

namespace rotacal::diagnosis_detail {

void judge_remainder(const SearchContext& S, const ModelFit& final_fit, Diagnosis& D) {
  const double n = static_cast<double>(final_fit.residuals.size());
  D.structure_after = residual_structure(S.P, final_fit.residuals);
  const int dof = static_cast<int>(n) - final_fit.num_free;
  const Eigen::VectorXd r_w = S.noise.whiten(final_fit.residuals);
  const double chi2_final = r_w.squaredNorm();
  D.unexplained.chi2_per_dof = chi2_final / dof;
  if (!S.noise.W) {
    D.unexplained.p_value = stats::chi2_sf(chi2_final, dof);
    const GroupResidual* worst = nullptr;
    for (const GroupResidual& g : D.structure_after)
      if (!worst || g.rms_um > worst->rms_um) worst = &g;
    if (worst) D.unexplained.group = worst->group;
  } else {
    // The noise of the group under test is modelled on the other groups (one AR model pooled
    // over them: the same sensor at the same rate): modelled on the group itself, the AR
    // model would take its structure for correlated noise and whiten it away, and with the
    // tested structure fitted first it would lose the noise's low frequencies with it and find
    // structure in every null session.
    const NoiseModel final_model =
        estimate_noise_model(S.layout, final_fit.residuals, S.options.noise);
    Eigen::MatrixXd Jfree = free_columns(final_fit.jacobian);
    int num_free = final_fit.num_free;
    // 1/f-like: stream levels are nuisance and the noise is AR(1) + a random walk by REML, as
    // in scoring; the Burg AR(p) of each group missed the wander and took it for structure
    // (31 of 200 1/f-like null sessions flagged). Pooled over every stream (three parameters),
    // one group's structure barely moves it.
    NoiseTreatment wander;
    if (final_model.max_order >= 2) {
      const Eigen::MatrixXd L = stream_levels(S.P);
      Eigen::MatrixXd X(Jfree.rows(), Jfree.cols() + L.cols());
      X << Jfree, L;
      num_free += static_cast<int>(orthonormal_basis(X).cols() - orthonormal_basis(Jfree).cols());
      Jfree = X;
      EffectModel final_effects;  // the model final_fit is the fit of: the findings'
      for (const Finding& F : D.findings) final_effects.effects.push_back(F.effect);
      wander = coloured_treatment(S.cache.level_walk(SearchCache::key(final_effects), final_model,
                                                     final_fit.residuals, Jfree));
    }
    NoiseModelOptions pooled = S.options.noise;
    pooled.pooled = true;
    pooled.pool_only_if_all_coloured = false;
    const NoiseModel pooled_all =
        estimate_noise_model(S.layout, final_fit.residuals, pooled);  // its streams
    // The other groups' pooled model, one per group tested: the same residual without one
    // group, its order searched up to the pooled order of all groups + 2 (as for the candidates).
    NoiseModelOptions others_options = pooled;
    others_options.max_order = std::min(pooled.max_order, pooled_all.max_order + 2);
    const auto whitener_for = [&](const std::string& group, const Eigen::MatrixXd&) {
      if (wander.W) return Whiten([wander](const Eigen::MatrixXd& M) { return wander.whiten(M); });
      NoiseTreatment t_noise = S.white;
      const NoiseStreamLayout others_layout = S.layout.except_group(group);
      // A session of one group (the probe's touches) has no other group to model its noise on:
      // its own model, whose AR part takes a share of slow structure, rather than white noise,
      // which took the correlation of every coloured null session for structure (AR(1) 0.5 and
      // 1/f-like probe sessions: 5 of 12 flagged; bench/structure_null.py).
      if (others_layout.rows.empty() && !final_model.white())
        t_noise = coloured_treatment(final_model, false);
      if (!others_layout.rows.empty()) {
        const NoiseModel others =
            estimate_noise_model(others_layout, final_fit.residuals, others_options);
        if (!others.white()) {
          NoiseModel all = pooled_all;
          const NoiseStream& o = others.streams.front();
          for (NoiseStream& st : all.streams) {
            st.reflection = o.reflection, st.ar = o.ar;
            st.marginal_sigma_um = o.marginal_sigma_um,
            st.innovation_sigma_um = o.innovation_sigma_um;
          }
          t_noise = coloured_treatment(all, false);
        }
      }
      return Whiten([t_noise](const Eigen::MatrixXd& M) { return t_noise.whiten(M); });
    };
    const StructureTest T = structure_test(S.P, final_fit.residuals, Jfree, num_free, whitener_for);
    D.unexplained.p_value = T.p_value;
    D.unexplained.group = T.group;
  }
  D.unexplained.present = D.unexplained.p_value < 1e-3;
  if (D.unexplained.present) {
    D.unexplained.signature = describe_structure(D.structure_after);
    if (!D.unexplained.group.empty()) {
      const Location L = locate(S.P, final_fit.residuals, D.unexplained.group);
      D.unexplained.axis = L.axis;
      D.unexplained.range_from = L.from;
      D.unexplained.range_to = L.to;
      std::ostringstream where;
      where.precision(4);
      where << "; in '" << D.unexplained.group << "' the residual is largest at "
            << (L.axis ? std::string(1, L.axis) + " " : std::string("t ")) << L.from << ".." << L.to
            << (L.axis ? " deg" : " s") << " (" << L.peak_um << " um mean there)";
      D.unexplained.signature += where.str();
      // A function of one rotary angle: offer the per-angle table as the extension.
      if (L.axis) {
        const NoiseModel left =
            estimate_noise_model(S.layout, final_fit.residuals, S.options.noise);
        AngleTable T = angle_table(S.P, final_fit.residuals, D.unexplained.group, left,
                                   S.noise.sigma_mm * 1e3, S.options.cv_blocks);
        if (T.gain.cv_rms_after_um < T.gain.cv_rms_before_um)
          D.angle_tables.push_back(std::move(T));
      }
    }
  }
}

}  // namespace rotacal::diagnosis_detail

namespace rotacal::diagnosis_detail {

namespace {

// A stream's residual level for the channels' F-test.
// Tested: half the sum of squared successive differences (von Neumann), which a slow wander of
// the noise barely reaches and a structure that changes from one commanded pose to the next
// does; reported: the level about the stream's mean.
struct StreamLevel {
  const NoiseStream* stream = nullptr;
  double ss = 0.0;        // sum of squared successive differences / 2, mm^2
  double level_ss = 0.0;  // sum of squares about the stream's mean, mm^2
  double dof = 0.0;       // its degrees of freedom: the readings less the fit's share of parameters
  double effective_dof = 0.0;  // dof over the scatter a correlated stream's variance has
};

// The step-down F-test of the channels' levels: the loudest channel against the pooled others,
// Bonferroni over the channels, at `alpha`; a loud channel found is left out of the reference
// and the next loudest tested against what is left (at least two channels stay quiet). Returns
// the loud ones (indices into `levels`) and the first test's p-value.
std::vector<std::size_t> loud_channels(const std::vector<StreamLevel>& levels, double alpha,
                                       double* p_first) {
  std::vector<std::size_t> loud;
  std::vector<bool> is_loud(levels.size(), false);
  const double k = static_cast<double>(levels.size());
  *p_first = 1.0;
  while (loud.size() + 3 <= levels.size()) {
    double best_p = 1.0;
    std::size_t best = 0;
    for (std::size_t i = 0; i < levels.size(); ++i) {
      if (is_loud[i]) continue;
      double ss = 0.0, dof = 0.0, eff = 0.0;
      for (std::size_t j = 0; j < levels.size(); ++j)
        if (j != i && !is_loud[j])
          ss += levels[j].ss, dof += levels[j].dof, eff += levels[j].effective_dof;
      const double F = (levels[i].ss / levels[i].dof) / (ss / dof);
      const double p = stats::f_sf(F, levels[i].effective_dof, eff);
      if (p < best_p) best_p = p, best = i;
    }
    if (loud.empty()) *p_first = std::min(1.0, best_p * k);
    if (best_p * k >= alpha) break;
    loud.push_back(best), is_loud[best] = true;
  }
  return loud;
}

// Where the structure in `rows` sits: the mean square of the residuals (each stream's mean
// removed) per distinct commanded angle of the axis that varies most there (per 1/12 of the
// time span where none varies), its peak over `noise_var`, and the run of bins around it
// whose excess is at least half the peak's. Fills D.unexplained's axis, range, at, size and
// suggested test.
void locate_noise_structure(const DiagnosisProblem& P, const Eigen::VectorXd& r,
                            const std::vector<const NoiseStream*>& streams, double noise_var,
                            Unexplained& U) {
  std::vector<std::pair<double, double>> xr;  // (coordinate, residual^2)
  double lo_t = 1e300, hi_t = -1e300, lo_r = 1e300, hi_r = -1e300;
  for (const NoiseStream* s : streams)
    for (Eigen::Index i : s->rows) {
      const RotaryAngles<double>& a = P.angles()[static_cast<std::size_t>(i)];
      lo_t = std::min(lo_t, a.tilt), hi_t = std::max(hi_t, a.tilt);
      lo_r = std::min(lo_r, a.rot), hi_r = std::max(hi_r, a.rot);
    }
  const bool rot = hi_r - lo_r >= hi_t - lo_t;
  const bool angle = std::max(hi_r - lo_r, hi_t - lo_t) > 1e-9;
  U.axis = angle ? (rot ? 'C' : tilt_axis_letter(P.machine())) : 0;
  for (const NoiseStream* s : streams) {
    double mean = 0.0;
    for (Eigen::Index i : s->rows) mean += r[i];
    mean /= static_cast<double>(s->rows.size());
    for (Eigen::Index i : s->rows) {
      const std::size_t u = static_cast<std::size_t>(i);
      const double x =
          !angle ? P.times()[u] : (rot ? P.angles()[u].rot : P.angles()[u].tilt) * 180.0 / M_PI;
      xr.emplace_back(x, (r[i] - mean) * (r[i] - mean));
    }
  }
  if (xr.empty()) return;
  std::sort(xr.begin(), xr.end());
  // Bins: the distinct angles (within 0.05 deg) where there are at most 72, else 24 equal bins.
  std::vector<double> centre, ms, cnt;
  const double lo = xr.front().first, hi = xr.back().first;
  std::vector<double> distinct;
  for (const auto& [x, e] : xr)
    if (distinct.empty() || x - distinct.back() > 0.05) distinct.push_back(x);
  const bool by_value = angle && distinct.size() <= 72;
  const int nb = by_value ? static_cast<int>(distinct.size()) : (angle ? 24 : 12);
  const double w = hi > lo ? (hi - lo) / nb : 1.0;
  centre.assign(static_cast<std::size_t>(nb), 0.0), ms = cnt = centre;
  std::size_t d = 0;
  for (const auto& [x, e] : xr) {
    while (by_value && d + 1 < distinct.size() && x - distinct[d] > 0.05) ++d;
    const std::size_t b =
        by_value ? d : static_cast<std::size_t>(std::min(nb - 1, static_cast<int>((x - lo) / w)));
    ms[b] += e, cnt[b] += 1.0;
  }
  for (int b = 0; b < nb; ++b) {
    const auto u = static_cast<std::size_t>(b);
    centre[u] = by_value ? distinct[u] : lo + (b + 0.5) * w;
    ms[u] = cnt[u] > 0 ? ms[u] / cnt[u] : 0.0;
  }
  const std::size_t peak =
      static_cast<std::size_t>(std::max_element(ms.begin(), ms.end()) - ms.begin());
  const double excess = ms[peak] - noise_var;
  U.at = centre[peak];
  U.size_um = std::sqrt(std::max(0.0, excess)) * 1e3;
  // The run around the peak (a full turn wraps around).
  const bool turn = angle && hi - lo >= 300.0;
  const auto step = [&](std::size_t b, int dir) -> long {
    const long next = static_cast<long>(b) + dir;
    if (next >= 0 && next < nb) return next;
    return turn ? (next + nb) % nb : -1;
  };
  const auto strong = [&](long b) {
    return b >= 0 && static_cast<std::size_t>(b) != peak &&
           ms[static_cast<std::size_t>(b)] - noise_var >= 0.5 * excess;
  };
  std::size_t first = peak, last = peak;
  for (int k = 0; k < nb - 1 && strong(step(first, -1)); ++k)
    first = static_cast<std::size_t>(step(first, -1));
  for (int k = 0;
       k < nb - 1 && strong(step(last, +1)) && step(last, +1) != static_cast<long>(first); ++k)
    last = static_cast<std::size_t>(step(last, +1));
  U.range_from = centre[first], U.range_to = centre[last];
  // Around the peak: between the sampled angles next to it, where the structure's shape is.
  const long before = step(peak, -1), after = step(peak, +1);
  std::ostringstream t;
  t.precision(4);
  if (by_value) {
    t << "more " << U.axis << " angles between "
      << (before >= 0 ? centre[static_cast<std::size_t>(before)] : centre[peak]) << " and "
      << (after >= 0 ? centre[static_cast<std::size_t>(after)] : centre[peak]) << " deg, around "
      << U.axis << " " << centre[peak] << " where it is largest (the session has " << nb
      << " distinct " << U.axis << " angles: a shape narrower than their spacing is seen at one "
      << "or two of them)";
  } else if (angle) {
    t << "a denser sweep of " << U.axis << " over " << U.range_from - w / 2 << ".."
      << U.range_to + w / 2 << " deg, and a repeat of it, to tell a shape in " << U.axis
      << " from a disturbance in time";
  } else {
    t << "a repeat of the session: a disturbance at t " << U.range_from - w / 2 << ".."
      << U.range_to + w / 2
      << " s does not recur at the same time, a drift or an error of the pose does";
  }
  U.suggested_test = t.str();
}

}  // namespace

void judge_noise_structure(const DiagnosisProblem& P, const DiagnosisOptions& options,
                           Diagnosis& D) {
  const Eigen::VectorXd& r = D.final_fit.residuals;
  const NoiseModel& M = D.noise;
  if (M.streams.empty() || static_cast<Eigen::Index>(M.n) != r.size()) return;
  const double n = static_cast<double>(r.size());
  const double fit_share = std::max(0.1, (n - D.final_fit.num_free) / n);
  // One instrument's streams: those of one session (multi_session.hpp names groups
  // "session:group").
  std::map<std::string, std::vector<const NoiseStream*>> by_instrument;
  for (const NoiseStream& s : M.streams)
    by_instrument[s.group.find(':') == std::string::npos ? std::string()
                                                         : s.group.substr(0, s.group.find(':'))]
        .push_back(&s);
  std::ostringstream what;
  what.precision(3);
  std::vector<const NoiseStream*> flagged;
  double p_value = 1.0, noise_var = 0.0;
  for (const auto& [instrument, streams] : by_instrument) {
    std::size_t shortest = SIZE_MAX;
    bool channels = false;
    for (const NoiseStream* s : streams)
      shortest = std::min(shortest, s->rows.size()), channels |= s->channel > 0;
    // (a) The levels of the instrument's channels (an R-test's dx, dy, dz at each nest).
    std::vector<StreamLevel> levels;
    std::vector<std::vector<double>> diffs;
    for (const NoiseStream* s : streams) {
      if (!channels || s->rows.size() < 8) break;
      StreamLevel L;
      L.stream = s;
      double mean = 0.0;
      for (Eigen::Index i : s->rows) mean += r[i];
      mean /= static_cast<double>(s->rows.size());
      for (Eigen::Index i : s->rows) L.level_ss += (r[i] - mean) * (r[i] - mean);
      diffs.emplace_back();
      for (std::size_t t = 1; t < s->rows.size(); ++t)
        diffs.back().push_back(r[s->rows[t]] - r[s->rows[t - 1]]);
      for (double d : diffs.back()) L.ss += 0.5 * d * d;
      L.dof = std::max(1.0, (static_cast<double>(s->rows.size()) - 1.0) * fit_share);
      levels.push_back(L);
    }
    // One inflation for every channel, as under the hypothesis tested the channels share one
    // noise process: 1 + 2 sum_k rho_k^2 (Bartlett 1946) over lags 1..n/4 of the differences,
    // rho_k the median over the channels of their sample autocorrelations (white noise: 1.5).
    // The channels' levels themselves, each with its own AR model, flagged 4 of 100 1/f-like
    // null R-test sessions (seeds 21000-21049), and with the loud channel's own model (the
    // structure's AR(8)) the test lost its power.
    if (!levels.empty()) {
      double inflation = 1.0;
      for (std::size_t k = 1; k <= shortest / 4; ++k) {
        std::vector<double> rho;
        for (const std::vector<double>& d : diffs) {
          double c0 = 0.0, ck = 0.0;
          for (std::size_t t = 0; t < d.size(); ++t) {
            c0 += d[t] * d[t];
            if (t >= k) ck += d[t] * d[t - k];
          }
          rho.push_back(c0 > 0.0 ? ck / c0 : 0.0);
        }
        std::nth_element(rho.begin(), rho.begin() + rho.size() / 2, rho.end());
        inflation += 2.0 * rho[rho.size() / 2] * rho[rho.size() / 2];
      }
      for (StreamLevel& L : levels) L.effective_dof = L.dof / inflation;
    }
    if (levels.size() >= 3 && levels.size() == streams.size()) {
      double p = 1.0;
      const std::vector<std::size_t> loud = loud_channels(levels, 0.01, &p);
      if (!loud.empty()) {
        double ss = 0.0, dof = 0.0;
        std::vector<bool> is_loud(levels.size(), false);
        for (std::size_t i : loud) is_loud[i] = true;
        for (std::size_t i = 0; i < levels.size(); ++i)
          if (!is_loud[i]) ss += levels[i].level_ss, dof += levels[i].dof;
        noise_var = ss / dof;
        p_value = std::min(p_value, p);
        what << (what.tellp() > 0 ? "; " : "")
             << "the noise levels of the channels differ (F-test, p " << p << "): ";
        for (std::size_t k = 0; k < loud.size(); ++k) {
          const StreamLevel& L = levels[loud[k]];
          flagged.push_back(L.stream);
          what << (k ? ", " : "") << "'" << L.stream->group << "' "
               << P.channel_name(L.stream->channel) << " " << std::sqrt(L.level_ss / L.dof) * 1e3
               << " um";
        }
        what << " against " << std::sqrt(noise_var) * 1e3 << " um in the other "
             << levels.size() - loud.size() << " channels";
      }
    }
    // (b) A high AR order on a short stream is structure: the largest order allowed (as
    // estimate_noise_model limits it: the option, and a quarter of the shortest stream pooled).
    const int limit = std::min(options.noise.max_order, static_cast<int>(shortest / 4));
    std::vector<const NoiseStream*> high;
    for (const NoiseStream* s : streams)
      if (limit >= 3 && s->rows.size() < 200 && s->order() >= limit) high.push_back(s);
    if (!high.empty()) {
      what << (what.tellp() > 0 ? "; " : "")
           << "its noise model took the largest AR order allowed, AR(" << high.front()->order()
           << "), on " << high.size() << " stream" << (high.size() > 1 ? "s" : "")
           << " of fewer than 200 readings ('" << high.front()->group << "' "
           << P.channel_name(high.front()->channel) << ": " << high.front()->rows.size() << ")";
      for (const NoiseStream* s : high)
        if (std::find(flagged.begin(), flagged.end(), s) == flagged.end()) flagged.push_back(s);
    }
  }
  if (flagged.empty()) return;
  Unexplained& U = D.unexplained;
  if (!(noise_var > 0.0)) {  // (b) alone: the noise as the model's innovations give it
    double v = 0.0, k = 0.0;
    for (const NoiseStream* s : flagged)
      v += s->innovation_sigma_um * s->innovation_sigma_um * 1e-6 *
           static_cast<double>(s->rows.size()),
          k += static_cast<double>(s->rows.size());
    noise_var = v / k;
  }
  U.noise_structure = what.str();
  U.noise_structure_p = p_value;
  U.noise_um = std::sqrt(noise_var) * 1e3;
  Unexplained located = U;
  locate_noise_structure(P, r, flagged, noise_var, located);
  std::ostringstream text;
  text.precision(4);
  text << "structure the noise model took for noise: " << U.noise_structure << "; it is largest at "
       << (located.axis ? std::string(1, located.axis) + " " : std::string("t ")) << located.at
       << (located.axis ? " deg" : " s") << " (" << located.size_um << " um RMS beyond "
       << U.noise_um << " um of noise, over " << located.range_from << ".." << located.range_to
       << (located.axis ? " deg" : " s") << "); to resolve it: " << located.suggested_test;
  U.size_um = located.size_um, U.at = located.at, U.suggested_test = located.suggested_test;
  // The noise the decisions were made with holds the structure: say so where it is reported.
  std::ostringstream held;
  held.precision(3);
  held << "; it holds structure (see unexplained): the instrument's noise is " << U.noise_um
       << " um";
  D.baseline.noise_source += held.str();
  if (U.present) {
    U.signature += "; " + text.str();
    return;
  }
  U.present = true;
  U.p_value = p_value;
  U.signature = text.str();
  U.group = flagged.front()->group;
  U.axis = located.axis, U.range_from = located.range_from, U.range_to = located.range_to;
}

}  // namespace rotacal::diagnosis_detail
