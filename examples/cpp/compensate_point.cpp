// SPDX-License-Identifier: BSD-3-Clause
// Load a rotacal-model/1 file (e.g. from `rotacal identify --save-model`) and compensate a point.
// Build: see examples/cpp/CMakeLists.txt; run: compensate_point MODEL.json TILT_DEG C_DEG X Y Z
// (X Y Z: the point wanted in the table frame, mm). Prints the nominal and the compensated
// machine axes, and checks that the compensated command reaches the point on the identified
// machine.
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <rotacal/io/model_file.hpp>
#include <rotacal/kinematics/machine.hpp>
#include <string>

namespace {
double number(const char* text, const char* what) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(v))
    throw rotacal::InvalidArgument(std::string(what) + ": '" + text + "' is not a finite number");
  return v;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::cerr << "usage: compensate_point MODEL.json TILT_DEG C_DEG X Y Z\n";
    return 2;
  }
  try {
    const rotacal::ModelFile model = rotacal::read_model(argv[1]);
    const double deg = M_PI / 180.0;
    const rotacal::RotaryAngles<double> angles{number(argv[2], "TILT_DEG") * deg,
                                               number(argv[3], "C_DEG") * deg};
    const Eigen::Vector3d p_table(number(argv[4], "X"), number(argv[5], "Y"), number(argv[6], "Z"));

    // Nominal command (no errors) and the command on the identified machine (Flynn et al.
    // Sec. 5: compensation = inverse kinematics with the identified location errors).
    const rotacal::LocationErrors<double> nominal;
    const rotacal::MachineAxes cmd0 = rotacal::inverse(model.machine, nominal, angles, p_table);
    const rotacal::MachineAxes cmd =
        rotacal::inverse(model.machine, model.location_errors, angles, p_table);

    std::cout << std::fixed << std::setprecision(6);
    std::cout << rotacal::to_string(model.machine) << " " << model.kind << " model, " << argv[1]
              << "\n";
    const auto& names = rotacal::location_error_names(model.machine);
    for (int k = 0; k < 8; ++k)
      std::cout << "  " << names[k] << " = "
                << (model.observable[static_cast<std::size_t>(k)]
                        ? std::to_string(model.location_errors.v[k])
                        : std::string("not determined (0)"))
                << (rotacal::location_error_is_angle(k) ? " rad\n" : " mm\n");
    std::cout << "nominal     X Y Z = " << cmd0.xyz.transpose() << "\n";
    std::cout << "compensated X Y Z = " << cmd.xyz.transpose() << "\n";
    std::cout << "correction (um)   = " << ((cmd.xyz - cmd0.xyz) * 1e3).transpose() << "\n";

    // On the identified machine the table point sits at forward(errors, angles, p_table) in
    // the machine frame: the compensated command must put the tool exactly there.
    const Eigen::Vector3d wanted =
        rotacal::forward(model.machine, model.location_errors, cmd.angles, p_table);
    const double miss_um = (cmd.xyz - wanted).norm() * 1e3;
    std::cout << "residual of the compensated command: " << std::setprecision(9) << miss_um
              << " um\n";
    return miss_um < 1e-6 ? 0 : 1;
  } catch (const rotacal::IoError& e) {
    std::cerr << e.what() << "\n";
    return 4;
  } catch (const rotacal::Error& e) {
    std::cerr << e.what() << "\n";
    return 3;
  }
}
