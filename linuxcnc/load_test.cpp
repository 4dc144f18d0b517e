// SPDX-License-Identifier: BSD-3-Clause
// rotacal-kins.so loaded as rtapi_app loads it (dlopen, the module parameters through their
// symbols, rtapi_app_main), without LinuxCNC: this executable provides the six HAL/RTAPI
// functions the module calls and records what it prints and which pins it makes. It checks that
// loading refuses a missing, corrupt, truncated, other-version or other-machine blob, naming the
// file and the field and making no pin (no partial load), and that a loaded module's
// kinematicsForward / kinematicsInverse are realtime::forward_world / inverse of the blob in
// degrees. The module in the real LinuxCNC: tests/python/test_linuxcnc_rotacal_kins.py.
//   test_rotacal_kins_load MODULE.so TMPDIR

#include <dlfcn.h>

#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "rotacal/realtime/blob.hpp"
#include "rotacal/realtime/evaluate.hpp"

// emcpos.h's EmcPose (tran x, y, z, then a, b, c, u, v, w), under its name.
struct EmcPose {
  double v[9];
};

namespace {
std::string g_printed;
std::vector<std::string> g_pins;
double g_pin_values[8];
int g_failures = 0;

void check(bool ok, const std::string& what) {
  if (!ok) {
    ++g_failures;
    std::printf("FAILED: %s\n", what.c_str());
  }
}
}  // namespace

// What the module takes from HAL and RTAPI (their C signatures, hal.h and rtapi.h).
extern "C" {
int hal_init(const char*) { return 7; }
int hal_exit(int) { return 0; }
int hal_ready(int) { return 0; }
void* hal_malloc(long size) {
  static double block[64];
  return size <= static_cast<long>(sizeof block) ? block : nullptr;
}
int hal_pin_float_newf(int, volatile double** data, int, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  char name[64];
  std::vsnprintf(name, sizeof name, fmt, ap);
  va_end(ap);
  *data = &g_pin_values[g_pins.size() % 8];
  **data = 0;
  g_pins.push_back(name);
  return 0;
}
void rtapi_print_msg(int, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  char line[512];
  std::vsnprintf(line, sizeof line, fmt, ap);
  va_end(ap);
  g_printed += line;
}
}

namespace {

using namespace rotacal::realtime;
using rotacal::EffectKind;

// An AC table-table machine with location errors and three effects (geometry written out, as
// tests/realtime/standalone.cpp does: this file links no rotacal library).
Model ac_machine() {
  Model m;
  Axis& a = m.axes[0];
  a.name = 'A';
  a.principal = 0;
  a.direction = Eigen::Vector3d::UnitX();
  a.position_basis << 0, 0, 1, 0, 0, 1;
  a.direction_basis << 0, 0, 0, 1, -1, 0;
  a.radial1 = Eigen::Vector3d::UnitY();
  a.radial2 = Eigen::Vector3d::UnitZ();
  Axis& c = m.axes[1];
  c.name = 'C';
  c.principal = 2;
  c.point = Eigen::Vector3d(0, 0, -50);
  c.position_basis << 1, 0, 0, 1, 0, 0;
  c.direction_basis << 0, 1, -1, 0, 0, 0;
  m.errors.v << 0.02, -0.015, 4e-5, -3e-5, 0.01, 0.025, -2e-5, 5e-5;
  m.thermal_gain(4, 0) = 0.003;
  const Term terms[] = {{EffectKind::angular_positioning, 'C', 1, 0},
                        {EffectKind::radial_motion, 'C', 2, 0},
                        {EffectKind::gravity_sag, 'A', 0, 0}};
  for (const Term& t : terms) {
    for (int i = 0; i < effect_num_params(t.kind); ++i, ++m.num_params)
      m.params[m.num_params] = 2e-5 * (i % 2 ? -1 : 1) * (m.num_params % 3 + 1);
    m.effects[m.num_effects++] = t;
  }
  return m;
}

struct Module {
  void* so;
  char** model;
  char** coordinates;
  int (*main)();
  // kinematics.h's signatures, to the type (UBSan checks calls through function pointers).
  int (*forward)(const double*, EmcPose*, const unsigned long*, unsigned long*);
  int (*inverse)(const EmcPose*, double*, const unsigned long*, unsigned long*);
};

std::string write(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// Loads with model=path coordinates=coords; returns rtapi_app_main's result.
int load(Module& mod, std::string path, const char* coords) {
  g_printed.clear();
  g_pins.clear();
  static char path_buf[512], coord_buf[32];
  std::snprintf(path_buf, sizeof path_buf, "%s", path.c_str());
  std::snprintf(coord_buf, sizeof coord_buf, "%s", coords);
  mod.model[0] = path_buf;
  *mod.coordinates = coord_buf;
  return mod.main();
}

void refused(Module& mod, const std::string& path, const char* coords, const char* field) {
  const int r = load(mod, path, coords);
  const std::string want = path + ": " + field;
  check(r < 0, std::string("refused: ") + field);
  check(g_printed.find(want) != std::string::npos,
        "names the file and " + std::string(field) + ", printed: " + g_printed);
  check(g_pins.empty(), std::string("no pin after a refused load: ") + field);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::printf("usage: test_rotacal_kins_load MODULE.so TMPDIR\n");
    return 2;
  }
  Module mod{};
  mod.so = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  if (!mod.so) {
    std::printf("dlopen: %s\n", dlerror());
    return 1;
  }
  // As rtapi_app finds a parameter: rtapi_info_address_NAME holds its address.
  const auto param = [&mod](const char* name) -> char** {
    void** at =
        static_cast<void**>(dlsym(mod.so, (std::string("rtapi_info_address_") + name).c_str()));
    return at ? static_cast<char**>(*at) : nullptr;
  };
  mod.model = param("model");
  mod.coordinates = param("coordinates");
  mod.main = reinterpret_cast<int (*)()>(dlsym(mod.so, "rtapi_app_main"));
  mod.forward = reinterpret_cast<decltype(mod.forward)>(dlsym(mod.so, "kinematicsForward"));
  mod.inverse = reinterpret_cast<decltype(mod.inverse)>(dlsym(mod.so, "kinematicsInverse"));
  check(mod.model && mod.coordinates && mod.main && mod.forward && mod.inverse,
        "the module exports its parameters and entry points");
  if (g_failures) return 1;

  const std::string dir = argv[2];
  const Model m = ac_machine();
  const std::string blob = encode(m);
  std::string corrupt = blob, version = blob;
  corrupt[kBlobHeaderBytes + 60] ^= 0x04;
  version[8] = 9;
  refused(mod, dir + "/missing.rtb", "XYZAC", "cannot open");
  refused(mod, write(dir + "/corrupt.rtb", corrupt), "XYZAC", "checksum");
  refused(mod, write(dir + "/cut.rtb", blob.substr(0, blob.size() - 40)), "XYZAC", "length");
  refused(mod, write(dir + "/version.rtb", version), "XYZAC", "version");
  // Another machine: the blob's rotary letters (A, C) are not the configured ones (B, C).
  refused(mod, write(dir + "/ac.rtb", blob), "XYZBC", "axes.name");

  check(load(mod, dir + "/ac.rtb", "XYZAC") == 0, "loads a good blob: " + g_printed);
  check(g_pins.size() == 4 && g_pins[0] == "rotacal-kins.tool-offset" &&
            g_pins[1] == "rotacal-kins.y1" && g_pins[2] == "rotacal-kins.y2",
        "its pins");
  g_pin_values[0] = 30;   // tool-offset
  g_pin_values[1] = 0.5;  // y1
  State s;
  s.tool_length = 30;
  s.y1 = 0.5;
  const double deg = M_PI / 180;
  double worst = 0;
  for (int i = 0; i < 50; ++i) {
    const double joints[5] = {-120.0 + 5 * i, 80.0 - 3 * i, 40.0 + i, -94.5 + 4 * i,
                              -300.0 + 13 * i};
    EmcPose world{};
    mod.forward(joints, &world, nullptr, nullptr);
    Joints q;
    q.xyz = Eigen::Vector3d(joints[0], joints[1], joints[2]);
    q.angles = {joints[3] * deg, joints[4] * deg};
    const Joints w = forward_world(m, q, s);
    worst = std::max({worst, (Eigen::Vector3d(world.v[0], world.v[1], world.v[2]) - w.xyz).norm(),
                      std::abs(world.v[3] - w.angles.tilt / deg),
                      std::abs(world.v[5] - w.angles.rot / deg)});
    double back[5];
    mod.inverse(&world, back, nullptr, nullptr);
    for (int j = 0; j < 5; ++j) worst = std::max(worst, std::abs(back[j] - joints[j]));
  }
  std::printf("forward_world in degrees and the round trip through the module: worst %.3g\n",
              worst);
  check(worst < 1e-8, "kinematicsForward is forward_world and kinematicsInverse undoes it");
  if (g_failures) return 1;
  std::printf("all checks passed\n");
  return 0;
}
