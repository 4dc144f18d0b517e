// Uses the installed package: where does a table point go on an AC-trt table with an E_X0C?
#include <rotacal/kinematics/machine.hpp>

#include <cmath>
#include <iostream>

int main() {
  rotacal::LocationErrors<double> e;
  e.v[rotacal::location_error_index(rotacal::MachineType::AC_trt, "E_X0C")] = 0.01;
  const Eigen::Vector3d p =
      rotacal::forward(rotacal::MachineType::AC_trt, e, {0.0, M_PI}, Eigen::Vector3d(0, 0, 50));
  std::cout << "table point (0,0,50) at C=180 deg with E_X0C=0.01 mm -> " << p.transpose() << "\n";
  // Turning by 180 deg about a C line offset by 0.01 mm moves the point by 0.02 mm in X.
  return std::abs(p.x() - 0.02) < 1e-12 ? 0 : 1;
}
