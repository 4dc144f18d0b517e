// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/diagnose: structure the final model leaves in a few consecutive poses, and the
// findings whose evidence lies in it (local_structure.cpp). An instrument that holds a pose for
// several readings (the touch probe: five touches of one sphere) gives each pose's readings the
// columns of a free local shift; a shape outside the catalogue that is local along a sweep or
// in time (a damaged stretch of a rotary table's track, a set-up knocked and settling back) is
// held by a few poses' shifts. A catalogue entry fitted to it is the catalogue's nearest shape,
// not the cause: it must not be named.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "rotacal/diagnose/diagnosis.hpp"

namespace rotacal::diagnosis_detail {

/// One held pose: its readings (rows of the problem, in order) and the columns of a free shift
/// of what the instrument sees there (rows.size() x k: for the probe, the sphere's X, Y, Z
/// shift, i.e. each touch's approach direction), with its commanded angles and time span.
struct LocalBlock {
  std::vector<Eigen::Index> rows;
  Eigen::MatrixXd columns;
  std::string label;
  double tilt_deg = 0.0, rot_deg = 0.0;
  double t_from = 0.0, t_to = 0.0;
};

/// On D's final model, `blocks` in the order they were measured, windows of 1..kMaxWindow
/// consecutive blocks:
///  - every finding weighed against its local rival, its own fitted signature free in each
///    block of one window and zero elsewhere, in its place (the best window at BIC's and at
///    AIC's Occam term): its weight becomes that among itself, its catalogue rivals and the
///    local rival (1 / (1 / w + e^(-delta IC / 2)), the smaller at the two terms). A finding
///    named alone before and below options.min_weight after, or one whose local rival fits at
///    least as well (delta IC <= 0 at either term), gets its Finding::lack_of_fit and is not
///    named alone: a finding that rests on a few poses is as well a defect there that the
///    catalogue does not hold;
///  - the blocks' free shifts F-tested against the final residuals (whitened under the noise the
///    final model leaves, its columns projected out), Bonferroni over the windows; where the
///    best window's p-value is below 1e-3, or else where a finding got its lack_of_fit, that
///    window is reported in D.unexplained (where, with its poses).
inline constexpr int kMaxWindow = 4;
void judge_local_structure(const DiagnosisProblem& P, const std::vector<LocalBlock>& blocks,
                           const DiagnosisOptions& options, Diagnosis& D);

}  // namespace rotacal::diagnosis_detail
