// SPDX-License-Identifier: BSD-3-Clause
// A controller vendor's build of the installed real-time headers: Eigen and the standard library,
// -fno-exceptions -fno-rtti, no rotacal library linked (CMakeLists.txt). A C line 0.01 mm off in
// X turns the tool tip seen from the table by 0.02 mm at C = 180 deg, and the inverse undoes it.
#include <cmath>
#include <cstdio>
#include <rotacal/realtime/blob.hpp>
#include <rotacal/realtime/evaluate.hpp>

int main() {
  rotacal::realtime::Model m;  // A along X under C along Z, through the origin
  m.axes[0].name = 'A';
  m.axes[0].principal = 0;
  m.axes[0].direction = Eigen::Vector3d::UnitX();
  m.axes[1].name = 'C';
  m.axes[1].principal = 2;
  m.axes[1].position_basis << 1, 0, 0, 1, 0, 0;  // E_X0C, E_Y0C
  m.errors.v[4] = 0.01;
  rotacal::realtime::Joints q;
  q.xyz = Eigen::Vector3d(0, 0, 50);
  q.angles.rot = M_PI;
  const rotacal::realtime::ToolPose p = rotacal::realtime::forward(m, q, {});
  std::printf("tip relative to the table at C = 180 deg with E_X0C = 0.01 mm: %g %g %g\n",
              p.tip.x(), p.tip.y(), p.tip.z());
  if (std::abs(p.tip.x() - 0.02) >= 1e-12) return 1;
  const std::string blob = rotacal::realtime::encode(m);
  rotacal::realtime::Model back;
  if (!rotacal::realtime::decode(blob.data(), blob.size(), 0, back).ok) return 1;
  q.angles.tilt = 0.5;
  const rotacal::realtime::InverseResult r = rotacal::realtime::inverse(back, q, {});
  return r.tip_error < 1e-8 ? 0 : 1;
}
