// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The thermal test of a rotary axis (../shared/spec/formats.md, "Thermal test of a rotary
/// axis"): an ordinary probe or R-test session with an `epoch` column (the rows measured in one
/// pause of the duty) and `# duty.N: TIME, AXIS=SPEED, ...` entries (from TIME on, each named
/// axis turns at SPEED rev/min, every other axis is at rest). io/thermal_file.hpp reads it.

#include <string>
#include <utility>
#include <vector>

#include "rotacal/kinematics/machine.hpp"
#include "rotacal/kinematics/thermal_lag.hpp"

namespace rotacal {

/// What a reader that pools the epochs (read_probe, read_session) says of a file with duty
/// lines (formats.md: it reads a thermal session as an ordinary one and warns that it drifts);
/// read_thermal_session, which fits the drift, leaves it out.
inline constexpr const char* kThermalSessionPooled =
    "a thermal session (# duty.N: lines): read as an ordinary session with its epochs pooled, "
    "though its location errors drift; `rotacal identify` fits the drift (docs/thermal.md)";

/// True for a metadata key of a duty entry ("duty.1", ...).
inline bool is_duty_key(const std::string& key) { return key.rfind("duty.", 0) == 0; }

/// One `# duty.N:` entry.
struct DutyEntry {
  double time = 0.0;                           ///< s, the rows' clock
  std::vector<std::pair<char, double>> speed;  ///< axis letter, rev/min (sign: direction)
  /// rev/min of `axis` from this entry on (0 when not named: at rest).
  double speed_of(char axis) const {
    for (const auto& s : speed)
      if (s.first == axis) return s.second;
    return 0.0;
  }
};

/// The duty and the epochs of a thermal session.
struct ThermalTest {
  std::vector<DutyEntry> duty;  ///< in file order, times strictly increasing
  std::vector<int> epoch;       ///< per row (sample), >= 1, non-decreasing
  std::vector<double> time;     ///< per row, s (the session's `time`)

  /// Axes the duty turns at some time, in order of first mention.
  std::vector<char> axes() const;
  /// First and last row time of each epoch, in order.
  std::vector<std::pair<double, double>> epoch_spans() const;
  /// u(t) of `axis` from the first row on: |speed| / 100 rev/min from the duty (0 before its
  /// first entry), 0 during every epoch (formats.md: the axes are held to measure).
  HeatInput heat_input(char axis) const;
  /// Largest |speed| the duty gives `axis`, rev/min (the tested speed).
  double tested_speed(char axis) const;
};

/// One lag of a simulated `thermal_location_R`: its time constant and gains (effects.md).
struct ThermalLagTruth {
  double tau_s = 1800.0;  ///< s
  ThermalGains<double> gains;
};

/// The drift rotacal's own simulators (probe/simulate.hpp, rtest/simulate.hpp) put on a machine:
/// their pattern measured once per epoch, from each of `epoch_start_s`, every axis held during
/// it, the duty turning `axis` between, and one or two lags of it.
struct ThermalSimSpec {
  std::vector<DutyEntry> duty;        ///< as a session's `# duty.N:` lines
  std::vector<double> epoch_start_s;  ///< s, strictly increasing: each epoch's first row
  char axis = 'C';                    ///< the axis whose motion heats (its lags below)
  std::vector<ThermalLagTruth> lags;  ///< one or two; empty: no drift (a null session)

  /// Throws InvalidArgument (naming `context` and the field) for no epoch, epochs closer than
  /// `epoch_length_s` (the pattern's own length) or not increasing, a duty the reader would
  /// refuse (times negative or not increasing, an axis `m` lacks), an axis `m` lacks, more
  /// than two lags or a tau not > 0.
  void validate(MachineType m, double epoch_length_s, const std::string& context) const;
  /// The rows' test: the duty, each row's epoch (1-based) and time.
  ThermalTest test(const std::vector<double>& time, const std::vector<int>& epoch) const;
  /// Each lag's state at each row of `test` (kinematics/thermal_lag.hpp), [lag][row].
  std::vector<std::vector<double>> lag_states(const ThermalTest& test) const;
  /// E0 + sum_l K_l y_l and q0 + sum_l Kq_l y_l at row i of `states`.
  LocationErrors<double> errors_at(const LocationErrors<double>& cold,
                                   const std::vector<std::vector<double>>& states,
                                   std::size_t i) const;
  Eigen::Vector3d point_at(const Eigen::Vector3d& cold,
                           const std::vector<std::vector<double>>& states, std::size_t i) const;
};

}  // namespace rotacal
