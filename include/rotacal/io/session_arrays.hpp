// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Sessions as columns and back: what array front ends (numpy) exchange with the library.
/// Building a session from columns validates it as the file reader would.

#include <optional>
#include <string>
#include <vector>

#include "rotacal/session/session.hpp"

namespace rotacal {

using RowMatrix3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using RowMatrix2 = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

std::vector<std::string> ballbar_tests(const BallbarSession& s);
Eigen::VectorXd ballbar_times(const BallbarSession& s);
RowMatrix3 ballbar_xyz(const BallbarSession& s);
RowMatrix2 ballbar_angles_deg(const BallbarSession& s);  ///< columns: tilt (A or B), C
Eigen::VectorXd ballbar_lengths(const BallbarSession& s);

/// A session from columns; throws InvalidArgument naming the column for a wrong length, a
/// non-finite value, a decreasing time, a non-positive length or L0.
BallbarSession make_ballbar_session(MachineType machine, double ballbar_length,
                                    const Eigen::Vector3d& pivot,
                                    const std::vector<std::string>& tests,
                                    const Eigen::VectorXd& time, const RowMatrix3& xyz,
                                    const RowMatrix2& angles_deg, const Eigen::VectorXd& length,
                                    std::optional<double> noise_um = std::nullopt);

/// The same session with new lengths (e.g. a model's prediction); throws InvalidArgument if
/// the count differs.
BallbarSession with_lengths(const BallbarSession& s, const Eigen::VectorXd& length);

std::vector<std::string> rtest_setups(const RtestSession& s);
Eigen::VectorXd rtest_times(const RtestSession& s);
RowMatrix2 rtest_angles_deg(const RtestSession& s);
RowMatrix3 rtest_xyz(const RtestSession& s);
/// dx,dy,dz (throws InvalidArgument if the session has raw readings only).
RowMatrix3 rtest_displacements(const RtestSession& s);
/// The same session with new dx,dy,dz.
RtestSession with_displacements(const RtestSession& s, const RowMatrix3& d);

}  // namespace rotacal
