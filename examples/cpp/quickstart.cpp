// SPDX-License-Identifier: BSD-3-Clause
// Identify the location errors of a ballbar session from C++.
// Build: see examples/cpp/CMakeLists.txt; run: quickstart SESSION.csv
#include <iostream>
#include <rotacal/ballbar/identify.hpp>
#include <rotacal/io/ballbar_file.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: quickstart SESSION.csv\n";
    return 2;
  }
  try {
    const rotacal::BallbarSession session = rotacal::read_ballbar(argv[1]);
    const rotacal::BallbarIdentification id = rotacal::identify_joint(session);
    for (const rotacal::ParameterEstimate& p : id.parameters) {
      if (p.observable)
        std::cout << p.name << " = " << p.value << " +- " << p.std << " " << p.unit << "\n";
      else
        std::cout << p.name << " is not determined by this session's tests\n";
    }
    std::cout << "residual RMS " << id.residual_rms_um << " um\n";
  } catch (const rotacal::Error& e) {
    std::cerr << e.what() << "\n";
    return 3;
  }
}
