// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The diagnosis of an R-test session: the DiagnosisProblem for the exact R-test reading,
///   d = T(B, C, t)^-1 * p_tool(xyz, t) - q_nest + zero_setup      (Oyama Eq. 4, in the table
///   frame)
/// with baseline = the 8 location errors (+ tool_offset_Z, minus the error of pivot_length +
/// tool_length, on a machine with head axes) + an unknown probe zero per set-up, and the
/// catalogue's effects (kinematics/effects.hpp) that exist on the machine as the candidate
/// extensions; on any machine of kinematics/machine_description.hpp. Every reading
/// has three components (dx, dy, dz); each is one residual.

#include <memory>

#include "rotacal/core/whitener.hpp"
#include "rotacal/diagnose/diagnosis.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

struct RtestArrays;

class RtestDiagnosisProblem : public DiagnosisProblem {
 public:
  /// Throws InvalidArgument if the session has no dx,dy,dz (convert raw probe readings first).
  explicit RtestDiagnosisProblem(RtestSession session);
  /// Optional noise model for every fit (GLS, core/joint_fit.hpp): 3 residuals per sample.
  std::shared_ptr<const ResidualWhitener> whitener;

  MachineType machine() const override { return session_.machine; }

  std::string instrument() const override { return "rtest"; }
  const std::vector<std::string>& groups() const override { return groups_; }
  const std::vector<double>& times() const override { return times_; }
  const std::vector<RotaryAngles<double>>& angles() const override { return angles_; }
  std::optional<double> declared_noise_um() const override { return session_.noise_um; }
  std::string channel_name(int channel) const override {  // the readings dx, dy, dz of a pose
    return channel >= 0 && channel < 3 ? std::string("d") + "xyz"[channel]
                                       : DiagnosisProblem::channel_name(channel);
  }
  Eigen::Vector3d mean_commanded_xyz() const override {
    return rotacal::mean_commanded_xyz(session_.samples);
  }
  /// The catalogue less the ballbar's own entries (and tool_offset_Z on a head machine, where
  /// it is in the baseline).
  std::vector<Effect> candidates(int max_harmonic) const override;
  ModelFit fit(const EffectModel& effects) const override { return fit_gls(effects, whitener); }
  ModelFit fit_gls(const EffectModel& effects,
                   std::shared_ptr<const ResidualWhitener> noise) const override;
  Eigen::MatrixXd candidate_jacobian(const ModelFit& at, const Effect& candidate) const override;
  std::vector<Eigen::MatrixXd> candidate_jacobians(
      const ModelFit& at, const std::vector<Effect>& candidates) const override;
  /// The candidate's Jacobian by Jets of all its parameters, without the harmonic shortcut
  /// (tests compare the two).
  Eigen::MatrixXd candidate_jacobian_by_jets(const ModelFit& at, const Effect& candidate) const;

 private:
  auto jets_at(const ModelFit& at) const;  // for src/diagnose/candidate_jets.hpp
  RtestSession session_;
  // The samples as the R-test problem's arrays (rtest/problem.hpp), built once for every refit.
  std::shared_ptr<const RtestArrays> arrays_;
  std::vector<std::string> groups_;  // per reading component
  std::vector<double> times_;
  std::vector<RotaryAngles<double>> angles_;
};

/// Diagnose an R-test session (see diagnosis.hpp).
Diagnosis diagnose_rtest(const RtestSession& session, const DiagnosisOptions& options = {});

}  // namespace rotacal
