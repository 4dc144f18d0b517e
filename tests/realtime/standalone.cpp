// SPDX-License-Identifier: BSD-3-Clause
// The real-time headers as a controller vendor builds them: this file includes only
// rotacal/realtime/, Eigen and the standard library, is compiled with -fno-exceptions -fno-rtti
// and links no rotacal library (tests/CMakeLists.txt). It checks what needs no library: no
// allocation in forward(), forward_world() and inverse(), the inverse's round trip, and the blob's
// refusals by field. The model's agreement with the fits' own evaluation is
// tests/cpp/test_realtime.cpp's.

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <string>

#include "rotacal/realtime/blob.hpp"
#include "rotacal/realtime/evaluate.hpp"

// Every allocation of the process, counted: forward() and inverse() must add none.
static std::atomic<long> g_allocations{0};
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  std::abort();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace {

int g_failures = 0;
void check(bool ok, const char* what, double value = 0) {
  if (!ok) {
    ++g_failures;
    std::printf("FAILED: %s (%g)\n", what, value);
  }
}

using rotacal::EffectKind;
using namespace rotacal::realtime;

// A table-table machine (A along X under C along Z) with a term of every kind that moves the
// tool or the table. The geometry is written out here because this file may not call the
// library's machine descriptions; its ISO 230-7 bases are the fits' business.
Model ac_table_machine() {
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
  c.direction = Eigen::Vector3d::UnitZ();
  c.point = Eigen::Vector3d(0, 0, -50);
  c.position_basis << 1, 0, 0, 1, 0, 0;
  c.direction_basis << 0, 1, -1, 0, 0, 0;
  m.table_axes = 2;
  m.rot = 1;
  m.errors.v << 0.02, -0.015, 4e-5, -3e-5, 0.01, 0.025, -2e-5, 5e-5;
  m.thermal_gain(4, 0) = 0.003;
  m.thermal_gain(0, 1) = -0.002;
  const Term terms[] = {
      {EffectKind::rotary_zero_offset, 'C', 0, 0},  {EffectKind::angular_positioning, 'C', 1, 0},
      {EffectKind::angular_positioning, 'A', 2, 0}, {EffectKind::radial_motion, 'C', 2, 0},
      {EffectKind::axial_motion, 'C', 1, 0},        {EffectKind::tilt_motion, 'A', 1, 0},
      {EffectKind::gravity_sag, 'A', 0, 0},         {EffectKind::coning, 'A', 0, 0},
      {EffectKind::linear_squareness, 'X', 0, 0},   {EffectKind::linear_scale, 'Z', 0, 0},
      {EffectKind::straightness, 'X', 0, 'Y'},      {EffectKind::linear_pitch, 'X', 0, 'B'},
      {EffectKind::rotary_backlash, 'C', 0, 0}};
  for (const Term& t : terms) {
    for (int i = 0; i < effect_num_params(t.kind); ++i) {
      m.params[m.num_params] = 1e-5 * (m.num_params % 7 + 1) * (i % 2 ? -1 : 1);
      ++m.num_params;
    }
    m.effects[m.num_effects++] = t;
  }
  m.linear_reference = Eigen::Vector3d(10, -5, 20);
  return m;
}

void no_allocation_and_round_trip(const Model& m) {
  State s;
  s.tool_length = 30;
  s.y1 = 0.4;
  s.y2 = 0.1;
  s.motion.direction.rot = 1;
  const long before = g_allocations.load();
  double worst_tip = 0, worst_dir = 0, sum = 0;
  for (int i = 0; i < 100000; ++i) {
    Joints world;
    world.xyz = Eigen::Vector3d(-100 + (i % 200), 80 - (i % 160), 40 + (i % 60));
    world.angles.tilt = -1.5 + 3.0 * ((i * 7919LL) % 1000) / 1000.0;
    world.angles.rot = -3.1 + 6.2 * ((i * 104729LL) % 1000) / 1000.0;
    const InverseResult inv = inverse(m, world, s);
    const ToolPose f = forward(m, inv.joints, s);
    const ToolPose target = forward(nominal_of(m), Joints{world.xyz, world.angles}, State{});
    if (std::abs(world.angles.tilt) > 0.02) {  // the rotary axis is free at tilt 0
      worst_tip = std::max(worst_tip, (f.tip - world.xyz).norm());
      worst_dir = std::max(worst_dir, (f.direction - target.direction).norm());
    }
    sum += f.tip.x() + forward_world(m, inv.joints, s).angles.rot;
  }
  const long allocations = g_allocations.load() - before;
  std::printf(
      "1e5 inverse, forward_world + 2e5 forward calls: %ld allocations; worst tip %.3g um, "
      "direction "
      "%.3g urad (checksum %.6g)\n",
      allocations, worst_tip * 1e3, worst_dir * 1e6, sum);
  check(allocations == 0, "no allocation in forward(), forward_world() and inverse()",
        double(allocations));
  check(worst_tip < 1e-5, "inverse round trip within 0.01 um", worst_tip * 1e3);
  check(worst_dir < 1e-8, "inverse round trip of the direction within 0.01 urad", worst_dir * 1e6);
}

void refused(const std::string& blob, const char* field, const Model& m, std::uint64_t machine) {
  Model out = ac_table_machine();
  out.errors.v[0] = 42;  // a model the caller holds already
  const LoadResult r = decode(blob.data(), blob.size(), machine, out);
  check(!r.ok && std::string(r.field) == field, field);
  if (r.ok || std::string(r.field) != field)
    std::printf("  expected field %s, got %s (%s)\n", field, r.field, r.reason);
  check(out.errors.v[0] == 42 && out.num_effects == m.num_effects, "no partial load");
}

void blob_refusals(const Model& m) {
  const std::string blob = encode(m);
  const std::uint64_t id = machine_fingerprint(m);
  Model back;
  const LoadResult ok = decode(blob.data(), blob.size(), id, back);
  check(ok.ok, "the blob reads back");
  check(encode(back) == blob, "and writes the same bytes");

  std::string corrupt = blob;
  corrupt[kBlobHeaderBytes + 100] ^= 0x10;
  refused(corrupt, "checksum", m, id);
  refused(blob.substr(0, blob.size() - 9), "length", m, id);
  refused(blob.substr(0, 12), "header", m, id);
  std::string version = blob;
  version[8] = 2;
  refused(version, "version", m, id);
  std::string magic = blob;
  magic[0] = 'X';
  refused(magic, "magic", m, id);
  Model other = m;  // the same model on a machine whose C line sits elsewhere
  other.axes[1].point.z() = 0;
  refused(encode(other), "machine", m, id);
  // A field that is wrong under a valid checksum is named too.
  Model bad_kind = m;
  bad_kind.effects[3].kind = static_cast<EffectKind>(200);
  refused(encode(bad_kind), "effects.kind", m, id);
  Model nan = m;
  nan.params[5] = std::nan("");
  refused(encode(nan), "params", m, id);
}

}  // namespace

int main() {
  const Model m = ac_table_machine();
  no_allocation_and_round_trip(m);
  blob_refusals(m);
  if (g_failures)
    std::printf("%d check(s) failed\n", g_failures);
  else
    std::printf("all checks passed\n");
  return g_failures ? 1 : 0;
}
