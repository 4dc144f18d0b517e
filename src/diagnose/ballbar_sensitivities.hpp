#pragma once
// Internal to src/diagnose: the ballbar candidates' Jacobians by the chain rule at the current
// fit, for a machine without head axes.
//
// Why: Jets of each candidate through the whole length model (the current model's stages and
// both axis rotations again for every candidate and row) were the largest part of a ballbar
// diagnosis. A candidate enters the reading only through the places listed in Sensitivity:
// an axis' angle, the pose of its error motion E or coning K (a left rotation and a
// translation), the table's translation D, the tool-side ball and the reading itself
// (effects.hpp composes them so). So
//   dL/dq = sum over places of (dL / d place, at the fit: once per row for all candidates)
//         x (d place / dq, from the candidate's own stages alone: Jets of one effect).
// The same derivatives as the Jets up to rounding; test_diagnose_ballbar.cpp checks them against
// candidate_jacobian_by_jets for every candidate of the catalogue.

#include <Eigen/Core>
#include <vector>

#include "rotacal/ballbar/motion.hpp"
#include "rotacal/diagnose/diagnosis.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal::diagnosis_detail {

class BallbarSensitivities {
 public:
  /// Machines whose ball pivot goes through every rotary axis (no head axes).
  static bool supports(MachineType m) { return !m.description().has_head(); }
  /// dL / d(each place) on every row of `samples` (with `motion`, one per sample) at fit `at`.
  BallbarSensitivities(MachineType m, const std::vector<BallbarSample>& samples,
                       const std::vector<RotaryMotion>& motion, const ModelFit& at);
  /// d L / d (the seeded parameters of `effect`), one column per seed (candidate_jets.hpp's
  /// `jets` contract), the effect's parameters at 0.
  Eigen::MatrixXd columns(const Effect& effect, const std::vector<int>& seed) const;

 private:
  // Rows of s_: the angle of chain axes 0 and 1; E's translation and left rotation (3 each) of
  // axes 0 and 1; K's left rotation of axes 0 and 1; the table translation D; the tool-side ball.
  enum Place { kAngle = 0, kEt = 2, kEw = 8, kKw = 14, kD = 20, kTool = 23, kPlaces = 26 };

  MachineType m_;
  const std::vector<BallbarSample>& samples_;
  const std::vector<RotaryMotion>& motion_;
  std::vector<RotaryAngles<double>> angles_;
  EffectModel reference_;  // no effects: the fit's linear_reference for the candidate's own stages
  Eigen::Matrix<double, kPlaces, Eigen::Dynamic> s_;
};

}  // namespace rotacal::diagnosis_detail
