// SPDX-License-Identifier: BSD-3-Clause
// Compensated commands for identified location errors, and the measure-compensate-remeasure check.
#include "rotacal/ballbar/compensate.hpp"

#include <cmath>

namespace rotacal {

BallbarSession compensate_commands(const BallbarSession& nominal,
                                   const LocationErrors<double>& identified, MachineType machine,
                                   double tool_length_error) {
  if (machine != nominal.machine)
    throw InvalidArgument("compensate_commands: identified model is for " + to_string(machine) +
                          " but the program is for " + to_string(nominal.machine));
  BallbarSession out = nominal;
  const LocationErrors<double> zero;
  for (BallbarSample& s : out.samples) {
    const RotaryAngles<double> a = s.angles_rad();
    // Table-frame target of the nominal (TCPM) command, then the command that reaches it on
    // the identified machine.
    const Eigen::Vector3d q = ball_in_table(machine, zero, a, s.xyz);
    s.xyz = inverse(machine, identified, a, q, tool_length_error).xyz;
  }
  return out;
}

double identified_tool_length_error(const BallbarMachineModel& model) {
  if (!model.machine.has_head()) return 0.0;
  const Effect tool_z = Effect::parse("tool_offset_Z");
  for (std::size_t i = 0; i < model.effects.effects.size(); ++i)
    if (model.effects.effects[i] == tool_z)
      return -model.effect_params[static_cast<std::size_t>(model.effects.offset(i))];
  return 0.0;
}

CompensationReport verify_compensation(const BallbarSession& commanded,
                                       const BallbarMachineModel& truth,
                                       const BallbarSimulationOptions& options,
                                       const JointFitOptions& fit) {
  CompensationReport r;
  const BallbarSession first = simulate_ballbar(commanded, truth, options);
  r.before = identify_joint(first, fit);

  // The machine runs the compensated program; the ballbar software still holds the nominal one.
  const BallbarSession program =
      compensate_commands(commanded, r.before.model.errors, truth.machine,
                          identified_tool_length_error(r.before.model));
  BallbarSimulationOptions second_options = options;
  second_options.seed = options.seed + 1;
  BallbarSession second = simulate_ballbar(program, truth, second_options);
  for (std::size_t i = 0; i < second.samples.size(); ++i)
    second.samples[i].xyz = commanded.samples[i].xyz;
  r.after = identify_joint(second, fit);

  for (int k = 0; k < 8; ++k) {
    CompensationRow row;
    const ParameterEstimate& b = r.before.parameters[static_cast<std::size_t>(k)];
    const ParameterEstimate& a = r.after.parameters[static_cast<std::size_t>(k)];
    row.name = b.name;
    row.unit = b.unit;
    row.before = b.value;
    row.after = a.value;
    row.std_after = a.std;
    row.change_percent =
        b.value != 0.0 ? 100.0 * (std::abs(a.value) - std::abs(b.value)) / std::abs(b.value) : 0.0;
    r.rows.push_back(row);
  }
  return r;
}

}  // namespace rotacal
