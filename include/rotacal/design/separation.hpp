// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The design engine: the information algebra of a joint fit and the one search for the
/// smallest added measurement that separates two effects after a session. Each instrument
/// only generates its candidates (ballbar: added tests from the session's or a moved pivot;
/// R-test: an added nest and its pose grid) as information matrices in the joint layout
/// (core/parameter_layout.hpp); the engine inverts, compares and chooses.
///
/// A candidate's information is the Fisher information J^T J w of its readings at the nominal
/// machine, in the joint layout of the session's parameters plus the candidate's own (a moved
/// pivot, an added nest's probe zero). Running it r = 1, 2, 4, ... times (or slowed down by r)
/// gathers r times the information, up to the time limit. The chosen candidate is the shortest
/// run that brings the largest canonical correlation of the pair below the target (the lower
/// correlation among equal runs); when none does, the one of lowest correlation.

#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "rotacal/core/noise_model.hpp"
#include "rotacal/core/parameter_layout.hpp"
#include "rotacal/design/table_motion.hpp"

namespace rotacal {

/// Covariance of an information matrix I (fit units) with the parameters the joint fit would
/// hold removed: one per combination that moving by the plausible magnitudes changes the white
/// chi-square (I x white) by less than 1 (analyse_observability), and any it still cannot see.
struct Inverted {
  Eigen::MatrixXd cov;  ///< zero rows and columns for held parameters
  std::vector<bool> determined;
  Eigen::VectorXd sigma;  ///< infinite for held parameters
};
Inverted invert_information(const Eigen::MatrixXd& I, const Eigen::VectorXd& plausible,
                            double white);

/// Largest canonical correlation between the determined parameters of block a and those of
/// block b (1 when either block has none).
double canonical_correlation(const Inverted& inv, const ParameterBlock& a, const ParameterBlock& b);

/// J's columns moved from one layout to another of `p` parameters: column block from[k] of J
/// goes to block to[k] (equal sizes); the other columns are zero.
Eigen::MatrixXd in_layout(const Eigen::MatrixXd& J, const std::vector<ParameterBlock>& from,
                          const std::vector<ParameterBlock>& to, Eigen::Index p);

/// What every instrument's separation design reports (the chosen candidate is the instrument's).
struct SeparationResult {
  std::array<std::string, 2> effects;
  TableMotionOverlap motion;
  /// Parameters of the joint fit: the session's, then the added measurement's own (absent
  /// from sigma_before).
  std::vector<std::string> names;
  Eigen::VectorXd
      sigma_before;  ///< session alone, 1 sigma, fit units; infinite: held (undetermined)
  Eigen::VectorXd sigma_after;      ///< session + the chosen candidate
  double correlation_before = 1.0;  ///< largest canonical correlation of the pair (1: undetermined)
  bool already_separated = false;   ///< the session alone is below max_correlation: nothing to add
  bool found = false;               ///< a candidate within the time limit reaches max_correlation
  int candidates_tried = 0;
  double noise_um = 0.0;               ///< used
  double effective_per_reading = 1.0;  ///< effective samples per reading (session's noise model)
  std::string verdict;                 ///< what to do, or why nothing can separate them
};

/// The session's side of the search.
struct SeparationProblem {
  Eigen::MatrixXd session_information;  ///< p0 x p0, the session's joint layout
  /// Plausible magnitude of every parameter (observability), at least as many as the largest
  /// candidate's layout.
  Eigen::VectorXd plausible;
  double white = 1.0;            ///< 1 / effective samples per reading
  ParameterBlock first, second;  ///< the pair's parameters (adjacent: first, then second)
  double max_correlation = 0.5;
  double max_added_time_s = 600.0;
};

/// The session's noise per reading into D (noise_um: `noise_um_option` when > 0, else the
/// noise model's sigma, else the fit's residual sigma; effective_per_reading from the noise
/// model) and the weight of its information, effective / sigma^2 (1 / mm^2). Throws
/// InvalidArgument with `zero_noise` when every sigma is zero.
double session_weight(double noise_um_option, const NoiseModel& noise, double fit_sigma_um,
                      const std::string& zero_noise, SeparationResult& D);

/// The problem of a session whose nominal Jacobian Js (session layout: the first columns of
/// `joint`) is weighted by w: plausible magnitudes by the units of `joint` (1 mm, 1 mrad, ...,
/// as the fit's observability test uses them), and D's effective samples per reading.
SeparationProblem separation_problem(const Eigen::MatrixXd& Js, double w,
                                     const ParameterLayout& joint, const ParameterBlock& first,
                                     const ParameterBlock& second, double max_correlation,
                                     double max_added_time_s, const SeparationResult& D);

/// One added measurement, in the joint layout (p >= p0 parameters; the session's first).
struct AddedInformation {
  double duration_s = 0.0;      ///< one run, s (within max_added_time_s)
  Eigen::MatrixXd information;  ///< p x p
  bool repeatable = true;       ///< may be run 2, 4, ... times (slowed down) to gather data
};

/// The search's answer (index: into the candidates; none when there was no candidate).
struct SeparationChoice {
  static constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
  std::size_t index = none;
  bool found = false;    ///< below max_correlation
  double repeats = 1.0;  ///< runs (or slow-down factor)
  double correlation = 1.0;
  bool determined = false;  ///< every parameter of both effects is determined
  Eigen::VectorXd sigma_after;
};

/// The session alone: fills sigma_before, correlation_before, and when no search is needed
/// (the pair moves the table alike, or the session already separates it) already_separated
/// and the verdict. Returns whether a search is needed.
bool separation_needed(const SeparationProblem& S, SeparationResult& D);

/// The search over `added` (in order; ties keep the first).
SeparationChoice search_separation(const SeparationProblem& S,
                                   const std::vector<AddedInformation>& added);

/// How the verdict names the instrument's candidates.
struct SeparationWording {
  std::string added = "added tests";        ///< "none of N <added> within ..."
  std::string seen_by = " of these tests";  ///< "no reading<seen_by> sees them"
  std::string closest_note = ": a longer test or another instrument may";
};

/// Fills found, sigma_after, the added measurement's parameter names and the verdict from the
/// search's choice and the chosen candidate's description (`run_s`: its run time, repeats
/// included; `added_names`: the chosen candidate's own parameters, appended to D.names).
void finish_separation(const SeparationProblem& S, const SeparationChoice& c,
                       const std::string& description, double run_s,
                       const std::vector<std::string>& added_names, const SeparationWording& w,
                       SeparationResult& D);

}  // namespace rotacal
