// SPDX-License-Identifier: BSD-3-Clause
// What the final model of a search leaves: its residual structure, the test for structure the
// noise does not explain (white: chi-square; coloured: per group against the other groups'
// noise model) and, where it is a function of one rotary angle, the per-angle table offered as
// the extension.
#include <algorithm>
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
