// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The error map per angle (Oyama Sec. 5.2, Figs. 6-7) from either identification, its JSON/CSV
/// writers, and the held-out check of a predictor. On any machine "B" is the tilt axis and "C"
/// the rotary axis; the columns carry the machine's letters and map names (rtest_map_names).
///
/// CSV columns: B, C (deg; the machine's tilt and rotary letters), then dx_BY .. gamma_BY,
/// dx_CB .. gamma_CB (mm, rad; the machine's map names), then the same with suffix _std
/// (1 sigma; empty where the data cannot determine the value).

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "rotacal/rtest/identify_joint.hpp"
#include "rotacal/rtest/identify_paper.hpp"

namespace rotacal {

struct RtestErrorMapEntry {
  double b_deg = 0.0, c_deg = 0.0;
  AxisErrors<double> w_BY = AxisErrors<double>::Zero(), w_BY_std = AxisErrors<double>::Zero();
  AxisErrors<double> w_CB = AxisErrors<double>::Zero(), w_CB_std = AxisErrors<double>::Zero();
};

struct RtestErrorMap {
  std::string method;  ///< "joint" or "paper"
  MachineType machine = MachineType::BC_trt;
  std::array<std::string, 2> maps = {"BY", "CB"};  ///< names of the tilt and rotary maps
  std::array<char, 2> letters = {'B', 'C'};        ///< tilt and rotary axis letters
  std::vector<RtestErrorMapEntry> entries;         ///< B outer, C inner
  std::vector<std::string> notes;
};

/// Map of the joint model on a grid (deg). Location errors are not in w_BY / w_CB here: the map
/// is the deviation beyond the rigid axis lines (identify_joint.hpp).
RtestErrorMap error_map(const RtestJointIdentification& id, const std::vector<double>& b_deg,
                        const std::vector<double>& c_deg);
/// Map of the paper's method at its measured grid (errors relative to B = C = 0, location
/// errors included, gamma_CB = 0).
RtestErrorMap error_map(const RtestPaperIdentification& id);

std::string error_map_csv(const RtestErrorMap& map);
std::string error_map_json(const RtestErrorMap& map);
/// Write either text to `path` by the output rule of rotacal/io/output_file.hpp; throws
/// IoError naming the path if it cannot be written.
void write_text_file(const std::string& path, const std::string& text);

/// Predicted reading of the nest at q (table frame) at (B, C) in rad.
using RtestPredictor = std::function<Eigen::Vector3d(const Eigen::Vector3d& q, double B, double C)>;

/// RMS (um, over all components) of measured - predicted readings of a session after removing
/// one constant offset per set-up (the probe zero is unknown in any new session).
double prediction_rms_um(const RtestSession& session, const RtestPredictor& predict);

}  // namespace rotacal
