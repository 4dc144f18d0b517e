// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The diagnosis of a touch-probe session: the DiagnosisProblem of the one probe problem
/// (probe/problem.hpp), baseline = location errors [+ tool_offset_Z on a head] + the sphere's
/// table position (identify_probe with no effects). Its candidates are the catalogue entries a
/// probe can see, with the probe's own stylus_radius_offset and probe_lobing: a wrong stylus
/// radius is named stylus_radius_offset.

#include <memory>

#include "rotacal/diagnose/diagnosis.hpp"
#include "rotacal/session/probe_session.hpp"

namespace rotacal {

class ProbeDiagnosisProblem : public DiagnosisProblem {
 public:
  explicit ProbeDiagnosisProblem(ProbeSession session);
  /// Optional noise model for every fit (GLS): one residual per touch.
  std::shared_ptr<const ResidualWhitener> whitener;

  MachineType machine() const override { return session_.machine; }

  std::string instrument() const override { return "probe"; }
  const std::vector<std::string>& groups() const override { return groups_; }
  const std::vector<double>& times() const override { return times_; }
  const std::vector<RotaryAngles<double>>& angles() const override { return angles_; }
  std::optional<double> declared_noise_um() const override { return session_.noise_um; }
  Eigen::Vector3d mean_commanded_xyz() const override {
    return rotacal::mean_commanded_xyz(session_.samples);
  }
  /// probe_effect_catalogue without the ballbar's own entries, the effects of motion (the
  /// touches are at rest) and, on a head, tool_offset_Z (in the baseline).
  std::vector<Effect> candidates(int max_harmonic) const override;
  /// One stream of ~120 touches: its lag-1 correlation, after the fit's 11 directions, comes out
  /// 0.43 +- 0.09 for a true 0.5, and the low sessions took the noise's slow part for an effect.
  double correlation_bound_z() const override;
  ModelFit fit(const EffectModel& effects) const override { return fit_gls(effects, whitener); }
  ModelFit fit_gls(const EffectModel& effects,
                   std::shared_ptr<const ResidualWhitener> noise) const override;
  /// Jets of the probe problem with the candidate appended at 0, the fit's values elsewhere.
  Eigen::MatrixXd candidate_jacobian(const ModelFit& at, const Effect& candidate) const override;

 private:
  ProbeSession session_;
  std::vector<std::string> groups_;
  std::vector<double> times_;
  std::vector<RotaryAngles<double>> angles_;
};

/// Diagnose a touch-probe session (see diagnosis.hpp).
Diagnosis diagnose_probe(ProbeSession session, const DiagnosisOptions& options = {});

}  // namespace rotacal
