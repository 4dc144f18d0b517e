#include "rotacal/kinematics/machine.hpp"

#include <cmath>

namespace rotacal {

std::string to_string(MachineType m) { return m == MachineType::AC_trt ? "AC-trt" : "BC-trt"; }

MachineType parse_machine_type(const std::string& s) {
  if (s == "AC-trt") return MachineType::AC_trt;
  if (s == "BC-trt") return MachineType::BC_trt;
  throw InvalidArgument("unknown machine '" + s + "' (known: AC-trt, BC-trt)");
}

char tilt_axis_letter(MachineType m) { return m == MachineType::AC_trt ? 'A' : 'B'; }

const std::array<std::string, 8>& location_error_names(MachineType m) {
  static const std::array<std::string, 8> ac = {"E_Y0A", "E_Z0A", "E_B0A", "E_C0A",
                                                "E_X0C", "E_Y0C", "E_A0C", "E_B0C"};
  static const std::array<std::string, 8> bc = {"E_X0B", "E_Z0B", "E_A0B", "E_C0B",
                                                "E_X0C", "E_Y0C", "E_A0C", "E_B0C"};
  return m == MachineType::AC_trt ? ac : bc;
}

int location_error_index(MachineType m, const std::string& name) {
  const auto& names = location_error_names(m);
  for (int i = 0; i < 8; ++i)
    if (names[i] == name) return i;
  throw InvalidArgument("'" + name + "' is not a location error of a " + to_string(m) +
                        " machine");
}

MachineAxes inverse(MachineType m, const LocationErrors<double>& e,
                    const RotaryAngles<double>& angles, const Eigen::Vector3d& p_table) {
  return {forward(m, e, angles, p_table), angles};
}

namespace {

// Spindle direction (machine +Z) seen in the table frame: R^T e_z.
Eigen::Vector3d tool_axis_in_table(MachineType m, const LocationErrors<double>& e,
                                   const RotaryAngles<double>& a) {
  return table_pose(m, e, a).R.transpose() * Eigen::Vector3d::UnitZ();
}

// Closed-form nominal solution. AC: R^T e_z = (sA sC, sA cC, cA); BC: (-sB cC, sB sC, cB).
RotaryAngles<double> nominal_angles(MachineType m, const Eigen::Vector3d& k, bool positive_tilt,
                                    double rot_hint) {
  RotaryAngles<double> a;
  const double kz = std::max(-1.0, std::min(1.0, k.z()));
  a.tilt = std::acos(kz) * (positive_tilt ? 1.0 : -1.0);
  const double s = std::sin(a.tilt);
  if (std::abs(s) < 1e-12) {  // tool axis along C: any C works, keep the caller's
    a.rot = rot_hint;
    return a;
  }
  a.rot = m == MachineType::AC_trt ? std::atan2(k.x() / s, k.y() / s)
                                   : std::atan2(k.y() / s, -k.x() / s);
  return a;
}

}  // namespace

MachineAxes inverse_with_tool_axis(MachineType m, const LocationErrors<double>& e,
                                   const Eigen::Vector3d& p_table, const Eigen::Vector3d& k_table,
                                   bool positive_tilt, double rot_hint) {
  const double n = k_table.norm();
  if (!(n > 0.0) || !std::isfinite(n))
    throw InvalidArgument("inverse_with_tool_axis: k_table must be a finite non-zero vector");
  const Eigen::Vector3d k = k_table / n;
  RotaryAngles<double> a = nominal_angles(m, k, positive_tilt, rot_hint);
  // Location errors are small (um, urad): a few Gauss-Newton steps on R(a)^T e_z = k converge.
  for (int it = 0; it < 10 && !e.v.isZero(0.0); ++it) {
    const Eigen::Vector3d r = tool_axis_in_table(m, e, a) - k;
    if (r.norm() < 1e-15) break;
    Eigen::Matrix<double, 3, 2> J;
    const double h = 1e-7;
    J.col(0) = (tool_axis_in_table(m, e, {a.tilt + h, a.rot}) - tool_axis_in_table(m, e, a)) / h;
    J.col(1) = (tool_axis_in_table(m, e, {a.tilt, a.rot + h}) - tool_axis_in_table(m, e, a)) / h;
    const Eigen::Vector2d step = J.colPivHouseholderQr().solve(-r);
    a.tilt += step[0];
    a.rot += step[1];
  }
  return inverse(m, e, a, p_table);
}

}  // namespace rotacal
