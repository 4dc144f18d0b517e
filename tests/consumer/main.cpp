// SPDX-License-Identifier: BSD-3-Clause
// Uses the installed package: where does a table point go on an AC-trt table with an E_X0C?
#include <cmath>
#include <iostream>
#include <rotacal/ballbar/model_document.hpp>
#include <rotacal/io/model_file.hpp>
#include <rotacal/kinematics/machine.hpp>

int main() {
  rotacal::LocationErrors<double> e;
  e.v[rotacal::location_error_index(rotacal::MachineType::AC_trt, "E_X0C")] = 0.01;
  const Eigen::Vector3d p =
      rotacal::forward(rotacal::MachineType::AC_trt, e, {0.0, M_PI}, Eigen::Vector3d(0, 0, 50));
  std::cout << "table point (0,0,50) at C=180 deg with E_X0C=0.01 mm -> " << p.transpose() << "\n";
  // Turning by 180 deg about a C line offset by 0.01 mm moves the point by 0.02 mm in X.
  if (std::abs(p.x() - 0.02) >= 1e-12) return 1;
  // The model file through the installed package (its nlohmann_json dependency found for us).
  rotacal::BallbarMachineModel m;
  m.errors = e;
  const rotacal::ModelFile f =
      rotacal::parse_model(rotacal::format_model(rotacal::ballbar_model_document(m)), "m");
  std::cout << "model file round trip: E_X0C = " << f.location_errors.v[4] << " mm\n";
  return f.location_errors.v == e.v ? 0 : 1;
}
