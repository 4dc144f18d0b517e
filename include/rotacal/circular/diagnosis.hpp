// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Diagnosis of ISO 230-4 ballbar circular tests of the linear axes: which classic causes
/// (squareness, scale mismatch, straightness, backlash, reversal spikes, servo mismatch, cyclic
/// error) the radial deviations support, each with its parameters, 1-sigma and gain. The
/// catalogue (docs/effects.md, "Linear-axis circular tests") is separate from the rotary
/// catalogue of kinematics/effects.hpp: its entries act on the linear axes at rotary zero,
/// and two of them (backlash, servo mismatch) depend on the direction of travel, which the
/// rotary fits do not model.
///
/// Model (first order in the errors: the reading changes by the actual ball's displacement
/// delta along the bar, e_r = (cos theta e_u + sin theta e_v)):
///   reading - L0 = sum over runs [c0 + c1 cos theta + c2 sin theta]      (baseline: centre
///                  offset and radius of each run, what ISO 230-4's LSQ circle removes)
///                + sum over entries  e_r . delta_entry(theta, omega, t)  + noise
/// with delta as in circular/simulate.hpp, at the commanded positions. The model is linear in
/// every parameter except two, which are profiled (every linear parameter refitted at each
/// trial): a spike's time constant (grid, then golden section on its log; 1-sigma from the
/// profile's curvature) and the reversal delay of backlash and spikes, the time from the
/// commanded reversal to the axis' own (its servo lag; the reversal is a step, so the profile
/// is a staircase: scanned, the middle of its lowest stair, 1-sigma half the range within
/// delta chi-square 1). Their uncertainty is carried into the linear parameters (half their
/// change between -1 and +1 sigma, added in quadrature).
///
/// Selection, with the thresholds of the rotary diagnosis (diagnosis.hpp): each round the
/// candidate with the most negative delta BIC is added if its F-test p-value,
/// Bonferroni-corrected over the candidates, is below alpha and its delta BIC below
/// min_delta_bic, until none is left; (1) first with the noise taken as white, its sigma from
/// successive differences (an AR model of the baseline's residuals would take the large
/// signatures for noise and whiten them away),
/// (2) then the noise modelled as AR (core/noise_model.hpp, pooled over the runs) from what
/// that model leaves, every entry whose drop-one test fails under it removed, (3) and forward
/// again under the AR model re-estimated each round, (4) once more backward after the
/// nonlinear parameters are refined: every decision that stands is made on whitened residuals
/// (GLS). A spike must stick outward (h > 0).
/// Parameters get 1-sigma from the final GLS fit. Entries the runs cannot determine are
/// reported unobservable with the reason: a plane or axis the session does not move, a
/// signature the baseline absorbs, or one that equals a finding's in these runs (squareness
/// and servo mismatch in one direction at one feed); the axes' own scales always (a circle
/// sees only their difference).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rotacal/circular/analysis.hpp"
#include "rotacal/core/estimate.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/diagnose/diagnosis.hpp"

namespace rotacal {

enum class CircularEffectKind {
  squareness,      ///< plane P = (u, v): u += s v (XY: x += s y; YZ: y += s z; ZX: z += s x); s rad
  scale_mismatch,  ///< plane P: u += dk/2 u, v -= dk/2 v; dk = k_u - k_v, mm/mm
  straightness,    ///< E_DA: D += c2 ((a_A - centre_A) / 100 mm)^2; c2 mm
  backlash,        ///< axis A trails by b/2 in its direction of travel; b mm, delay s
  reversal_spike,  ///< axis A stays behind by h exp(-dt/tau) after reversing; h mm, tau s, delay s
  servo_mismatch,  ///< plane P: lag time constants differ, dtau = tau_u - tau_v, s
  cyclic_error,    ///< axis A += c cos(2 pi a / p) + d sin(2 pi a / p); c, d mm
};

/// One catalogue entry.
struct CircularEffect {
  CircularEffectKind kind = CircularEffectKind::squareness;
  CircularPlane plane = CircularPlane::XY;  ///< plane entries
  int axis = 0;       ///< axis entries: 0, 1, 2 = X, Y, Z; straightness: the moving axis A
  int direction = 0;  ///< straightness: the error direction D

  /// "squareness_XY", "scale_mismatch_XY", "straightness_YX" (D then A), "backlash_X",
  /// "reversal_spike_X", "servo_mismatch_XY", "cyclic_error_X".
  std::string id() const;
  /// Throws InvalidArgument naming the id and the catalogue's ids if it is not one of them.
  static CircularEffect parse(const std::string& id);
  std::vector<std::string> param_names() const;
  std::vector<std::string> param_units() const;
  std::string cause() const;
};

/// Every entry: 3 squareness, 3 scale mismatch, 6 straightness, 3 backlash, 3 reversal spike,
/// 3 servo mismatch, 3 cyclic error.
std::vector<CircularEffect> circular_catalogue();

struct CircularDiagnosisOptions {
  double alpha = 0.01;           ///< family-wise false-finding rate per round (Bonferroni)
  double min_delta_bic = -10.0;  ///< "very strong" on the Kass-Raftery scale
  int max_findings = 10;
  /// Lead of each axis' screw (X, Y, Z), mm: the period of its cyclic error.
  Eigen::Vector3d screw_pitch = Eigen::Vector3d::Constant(10.0);
  std::vector<std::string> only;  ///< restrict candidates to these ids (empty: all)
  bool model_noise = true;        ///< AR noise model and GLS; false: white noise
  int cv_blocks = 5;              ///< contiguous blocks per run for cross-validation
  /// A candidate is visible when moving its parameters by plausible sizes (5 um, 50 urad,
  /// 50 um/m, 1 ms) beyond what the model absorbs changes chi-square by at least this much.
  double min_visible_chi2 = 25.0;
};

struct CircularFinding {
  std::string effect;  ///< catalogue id
  std::string cause;
  std::vector<ParameterEstimate> parameters;  ///< final fit, 1-sigma from GLS
  /// Residual RMS of the final model without this entry (refitted) and with it, delta BIC and
  /// F-test p-value of the comparison, and the blocked cross-validated RMS of both.
  Gain gain;
};

struct CircularDiagnosis {
  std::size_t n = 0;
  double baseline_rms_um = 0.0;  ///< residual RMS of centre + radius per run
  double final_rms_um = 0.0;
  NoiseModel noise;  ///< of the final residuals
  bool noise_whitened = false;
  std::vector<CircularFinding> findings;  ///< in the order they were added
  std::vector<UnobservableEffect> unobservable;
  /// Every visible candidate scored against the baseline with the noise taken as white (step 1),
  /// best (most negative delta BIC) first.
  std::vector<CandidateScore> first_round;
  Eigen::VectorXd residuals_mm;  ///< final model, one per circular reading in run order
};

/// Diagnose the circular runs of a session (circular/analysis.hpp names the runs). Throws
/// InvalidArgument for unknown ids in options.only, a non-positive screw pitch, alpha outside
/// (0, 1), and the errors of circular_runs.
CircularDiagnosis diagnose_circular(const BallbarSession& session,
                                    const CircularDiagnosisOptions& options = {});

}  // namespace rotacal
