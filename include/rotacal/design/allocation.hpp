// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The design engine's allocation: how many runs of each candidate measurement (for the touch
/// probe: a pose with its touches) to take, for a given total number of runs, so that the
/// largest expanded uncertainty of a block of parameters (the location errors) is smallest.
/// Each instrument only generates its candidates, as information matrices in one layout
/// (design/separation.hpp); the covariance of a design is invert_information's.
///
/// The search: the continuous design (weights w_k over the candidates, information
/// M(w) = sum w_k A_k) minimising the largest scaled variance v_j = s_j^2 [M^-1]_jj, as the
/// largest over weights lam on the target of sum_j lam_j v_j: for given lam the weighted
/// A-optimal design by the multiplicative algorithm w_k <- w_k (d_k / sum_i w_i d_i)^(1/2),
/// d_k = tr(M^-1 L M^-1 A_k), L = diag(lam_j s_j^2) (Silvey, Titterington and Torsney 1978,
/// Pukelsheim 1993 ch. 9), then lam_j <- lam_j exp(2 (v_j / max v - 1)) towards the largest
/// variances (40 x 10 steps, the w of the smallest max v kept), on the parameters the
/// candidates together determine; the weights rounded to runs by
/// Pukelsheim and Rieder's efficient rounding (1992); then single runs moved from one candidate
/// to another while the largest expanded uncertainty (invert_information) decreases (among more
/// than 400 candidates, to one of the 16 with the largest d_k at lam_j ~ v_j^63, the derivative
/// of the smooth maximum (sum_j v_j^64)^(1/64)).

#include <Eigen/Core>
#include <limits>
#include <vector>

#include "rotacal/core/parameter_layout.hpp"
#include "rotacal/design/separation.hpp"

namespace rotacal {

/// Candidates, the budget and the target of an allocation.
struct AllocationProblem {
  std::vector<Eigen::MatrixXd>
      candidates;         ///< information of one run of each candidate, p x p (fit units)
  int runs = 0;           ///< total runs to allocate
  ParameterBlock target;  ///< the parameters whose largest expanded uncertainty counts
  Eigen::VectorXd
      scale;  ///< per target parameter: expanded uncertainty per unit of sigma (e.g. 2 x 1e3 um/mm)
  Eigen::VectorXd plausible;  ///< per parameter of the layout, as invert_information takes them
  double white = 1.0;         ///< as invert_information takes it
};

/// The largest expanded uncertainty of a design.
struct DesignUncertainty {
  double worst =
      std::numeric_limits<double>::infinity();  ///< max over the target of scale_j sigma_j
  Eigen::Index worst_index = -1;                ///< its layout index
  bool feasible = false;                        ///< every parameter of `required` is determined
};

/// scale_j sigma_j over the target's determined parameters, and whether every target parameter
/// marked in `required` (target order) is determined.
DesignUncertainty design_uncertainty(const Inverted& inv, const ParameterBlock& target,
                                     const Eigen::VectorXd& scale,
                                     const std::vector<bool>& required);

/// The engine's answer.
struct Allocation {
  std::vector<int> counts;         ///< runs of each candidate, summing to problem.runs
  Inverted inverted;               ///< of sum counts_k A_k
  DesignUncertainty uncertainty;   ///< of it
  std::vector<bool> determinable;  ///< per target parameter: determined by all candidates together
};

/// Allocate the runs. A target parameter that no combination of candidates determines is left
/// out of the criterion (determinable false) and may stay held. Throws InvalidArgument for no
/// candidate, runs < 1, matrices or scales of the wrong size.
Allocation allocate_runs(const AllocationProblem& problem);

}  // namespace rotacal
