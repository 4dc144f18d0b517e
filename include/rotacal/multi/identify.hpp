// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// One identification from several sessions of one machine (issue 31, item 5): ballbar,
/// R-test and touch-probe sessions fitted together for ONE set of location errors, each session
/// keeping its own nuisance parameters (ballbar pivot; R-test probe zeros and tool offset;
/// probe sphere) and its own noise model.
///
/// The layer sits above the instrument problems (ballbar/problem.hpp, rtest/problem.hpp,
/// probe/problem.hpp), which do not know each other: each session's residual model is the
/// instrument's own, and the stacked model only maps its location-error columns onto the one
/// shared block (core/parameter_layout.hpp). The sequence per session is the instruments'
/// (core/fit_with_noise.hpp): white fit alone -> noise model of its residuals -> [GLS]; the
/// joint fit then whitens each session's rows by that session's model (core/block_whitener.hpp).
///
/// The sessions alone are also compared: a location error seen by two sessions whose
/// difference exceeds a threshold (`disagreement_alpha` over all comparisons, at least
/// `disagreement_z`) in sigmas of the difference is reported as a disagreement
/// (which parameter, which sessions, by how much) rather than averaged silently, and so is a
/// joint value that lies outside every session's own (session_b then "joint fit"). While
/// sessions disagree the joint values describe no machine: the model document refuses them
/// (multi/model_document.hpp) unless `inflate_sigma` widened their sigmas by the scatter.

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "rotacal/core/estimate.hpp"
#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/identification.hpp"
#include "rotacal/core/noise_handling.hpp"
#include "rotacal/kinematics/effects.hpp"
#include "rotacal/kinematics/machine.hpp"

namespace rotacal {

struct BallbarSession;
struct RtestSession;
struct ProbeSession;

/// One session of a multi-session identification, by instrument. Build with the factories.
struct MultiSessionInput {
  std::string name;        ///< how the session is named in the result (e.g. its file)
  std::string instrument;  ///< "ballbar", "rtest" or "probe"
  std::shared_ptr<const BallbarSession> ballbar;
  std::shared_ptr<const RtestSession> rtest;
  std::shared_ptr<const ProbeSession> probe;
  /// Empty, or the name of an earlier session of the same instrument whose set-up this one
  /// continues with nothing moved between them (a test added to a session with the ball left in
  /// its cup, a nest whose label and fixture stayed): the two share their own parameters of the
  /// same name (the pivot; the probe zero of a nest of that label; the sphere) instead of
  /// fitting one each.
  std::string same_setup_as;

  static MultiSessionInput of(std::string name, BallbarSession session);
  static MultiSessionInput of(std::string name, RtestSession session);
  static MultiSessionInput of(std::string name, ProbeSession session);
  MachineType machine() const;
};

struct MultiFitOptions {
  /// Catalogue effects of the machine fitted along, ONE set shared by every session (each
  /// session's instrument must model them). Their linear-axis polynomials are about
  /// effects.linear_reference, the machine zero when unset, the same for every session.
  EffectModel effects;
  /// `automatic`: a session whose residuals are correlated is whitened by its AR model (GLS),
  /// as in its single-instrument fit; `white`: each session weighted by its residual sigma.
  /// allow_reml applies to the sessions whose instrument's own fit allows it (the R-test's).
  NoiseFitOptions noise = [] {
    NoiseFitOptions o;
    o.noise = NoiseHandling::automatic;
    o.allow_reml = true;
    return o;
  }();
  int max_iterations = 100;
  double observability_min_chi2 = 1.0;
  /// Probability that sessions of one machine are reported to disagree on anything: the
  /// threshold on |difference| / sigma of the difference is Bonferroni's over every comparison
  /// made (pairs of sessions x parameters both determine), so more sessions need a larger abs(z).
  double disagreement_alpha = 0.01;
  /// The threshold never goes below this abs(z) (a single comparison at alpha 1 % would be 2.58).
  double disagreement_z = 3.0;
  /// When sessions disagree, widen the sigma of each parameter they disagree on by its Birge
  /// ratio (the scatter of the sessions alone about the joint value, sqrt(chi2 / (n - 1))),
  /// the user's choice to keep a joint model anyway; the result says so in its notes.
  bool inflate_sigma = false;
};

/// The name a disagreement between one session and the joint value gives its second side.
inline constexpr const char* kJointFitSide = "joint fit";

/// Two sessions alone disagree on one location error (or shared effect parameter).
struct MultiDisagreement {
  std::string parameter, unit;
  std::string session_a, session_b;
  double value_a = 0.0, value_b = 0.0;
  double difference = 0.0;  ///< value_a - value_b
  double sigma = 0.0;       ///< 1 sigma of the difference (independent sessions)
  double z = 0.0;           ///< difference / sigma
  /// Degrees of freedom of `sigma` (Welch-Satterthwaite over the two sessions' own: each
  /// sigma rests on its noise model's effective samples less its free parameters).
  double dof = std::numeric_limits<double>::infinity();
  double threshold = 0.0;  ///< the abs(z) beyond which it is a disagreement, at `dof`
};

/// What one session contributes.
struct MultiSessionResult {
  std::string name, instrument;
  /// Its own parameters in the joint fit (those shared by same_setup_as included).
  std::vector<ParameterEstimate> nuisances;
  std::vector<ParameterEstimate> alone;  ///< its location errors (then shared effects) fitted alone
  NoiseModel noise;                      ///< noise model of its residuals alone
  /// Degrees of freedom of its sigmas alone: the noise model's effective samples less the
  /// free parameters of its fit alone.
  double dof = std::numeric_limits<double>::infinity();
  bool noise_refit = false;       ///< whitened by `noise` (GLS) in the joint fit
  double noise_correction = 1.0;  ///< bias factor on its share of the covariance
  double residual_rms_um = 0.0;   ///< of the joint fit, this session's rows
  std::size_t n_residuals = 0;
};

/// The joint identification, an Identification (core/identification.hpp) whose parameter
/// vector holds the blocks "location_errors" (the one shared set), "effects" (the shared
/// catalogue effects' parameters, empty unless asked) and then one block per session, named
/// after it, of its own parameters ("name:parameter"; a session with same_setup_as holds only
/// those its earlier session has not). Its covariance, residuals (the sessions'
/// rows back to back), unobservable combinations, notes and solver figures are the joint fit's;
/// `noise` is left white: each session has its own (MultiSessionResult::noise).
struct MultiIdentification : Identification {
  MachineType machine = MachineType::AC_trt;
  EffectModel effect_model;                  ///< the shared catalogue effects (options.effects)
  std::vector<MultiSessionResult> sessions;  ///< in input order
  std::vector<MultiDisagreement> disagreements;
  bool sigma_inflated = false;  ///< inflate_sigma widened the sigmas of disagreeing parameters
  std::size_t comparisons = 0;  ///< pairs of sessions x parameters both determine
  /// The abs(z) beyond which one of them is a disagreement with exactly known sigmas; a
  /// comparison of sigmas from few effective samples has its own (MultiDisagreement::threshold).
  double disagreement_z = 0.0;
  /// The one shared set of location errors (block "location_errors").
  std::vector<ParameterEstimate> location_errors() const { return block("location_errors"); }
  /// The shared catalogue effects' parameters (block "effects").
  std::vector<ParameterEstimate> effects() const { return block("effects"); }
  /// The shared location error called `name`; throws InvalidArgument when there is none.
  const ParameterEstimate& location_error(const std::string& name) const;
};

/// The joint identification. Throws InvalidArgument for fewer than two sessions, sessions of
/// different machine types (naming them), a session without data, repeated names, or a
/// same_setup_as that names no earlier session of the same instrument.
MultiIdentification identify_multi(const std::vector<MultiSessionInput>& sessions,
                                   const MultiFitOptions& options = {});

}  // namespace rotacal
