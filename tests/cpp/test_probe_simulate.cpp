// SPDX-License-Identifier: BSD-3-Clause
// The touch-probe simulator (probe/simulate.hpp) against the independent implementation's
// session: with the truth file's errors and sphere it reproduces the latched positions of
// ../shared/data/probe_ac_table2.csv to within their noise, and the nominal machine does not.
#include <catch2/catch.hpp>
#include <fstream>
#include <sstream>

#include "rotacal/io/probe_file.hpp"
#include "rotacal/probe/simulate.hpp"
#include "rotacal/probe/touch_model.hpp"

using namespace rotacal;

namespace {
const std::string kShared = ROTACAL_SHARED_DIR;

// The numbers of a "key": [x, y, z] or "key": value entry of the truth JSON (flat enough here).
std::vector<double> truth_numbers(const std::string& text, const std::string& key, int count) {
  const std::size_t at = text.find("\"" + key + "\"");
  REQUIRE(at != std::string::npos);
  std::vector<double> out;
  std::istringstream in(text.substr(text.find(':', at) + 1));
  char c;
  while (static_cast<int>(out.size()) < count && in >> c) {
    if (c == '[' || c == ',' || c == ' ') continue;
    in.putback(c);
    double v;
    in >> v;
    out.push_back(v);
  }
  return out;
}

// The pattern of a session: its poses, the directions of its first pose, its artefact.
ProbePattern pattern_of(const ProbeSession& s) {
  ProbePattern p;
  for (const std::string& pose : s.poses()) {
    const ProbeSample& x = s.samples[s.indices_of(pose).front()];
    p.poses_deg.push_back({x.tilt_deg, x.rot_deg});
  }
  for (std::size_t i : s.indices_of(s.poses().front())) p.directions.push_back(s.samples[i].n);
  p.sphere = s.sphere;
  p.sphere_diameter = s.sphere_diameter;
  p.stylus_diameter = s.stylus_diameter;
  return p;
}

double rms_um(const ProbeSession& a, const ProbeSession& b) {
  double ss = 0.0;
  for (std::size_t i = 0; i < a.samples.size(); ++i)
    ss += (a.samples[i].xyz - b.samples[i].xyz).squaredNorm();
  return std::sqrt(ss / (3.0 * static_cast<double>(a.samples.size()))) * 1e3;
}
}  // namespace

TEST_CASE("the simulator reproduces the independent probe session", "[probe][convention]") {
  const ProbeSession file = read_probe(kShared + "/data/probe_ac_table2.csv");
  std::ifstream in(kShared + "/data/probe_ac_table2.truth.json");
  const std::string truth((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  MachineModel m = MachineModel::nominal(MachineType::AC_trt);
  const auto& names = location_error_names(m.machine);
  for (int k = 0; k < 8; ++k)
    m.errors.v[k] = truth_numbers(truth, names[static_cast<std::size_t>(k)], 1)[0];
  const std::vector<double> sphere = truth_numbers(truth, "sphere_actual", 3);
  ProbeSimOptions o;
  o.pattern = pattern_of(file);
  o.sphere_offset = Eigen::Vector3d(sphere[0], sphere[1], sphere[2]) - file.sphere;
  o.noise_um = 0.0;
  const ProbeSession sim = simulate_probe(m, o).session;
  REQUIRE(sim.samples.size() == file.samples.size());
  const double noise = truth_numbers(truth, "noise_um", 1)[0];
  CHECK(rms_um(sim, file) == Approx(noise).margin(0.15 * noise));
  // Teeth: without the location errors the positions are far off.
  CHECK(rms_um(simulate_probe(MachineModel::nominal(MachineType::AC_trt), o).session, file) >
        5 * noise);
}

TEST_CASE("simulated touches lie on the truth's sphere, noise as asked", "[probe]") {
  for (const char* name : {"AC-trt", "BC-trt", "B-head-C-table"}) {
    MachineModel m = MachineModel::nominal(parse_machine_type(name));
    m.errors.v << 0.03, -0.02, 2e-5, -3e-5, 0.01, 0.04, -1e-5, 2e-5;
    m.effects = EffectModel{{Effect::parse("stylus_radius_offset"), Effect::parse("probe_lobing"),
                             Effect::parse("angular_positioning_C_h1")},
                            std::nullopt};
    m.effect_params = {2e-3, 0.8e-3, -0.4e-3, 2e-5, 1e-5};
    ProbeSimOptions o;
    o.pattern = default_probe_pattern(m.machine);
    o.sphere_offset = Eigen::Vector3d(0.05, -0.03, 0.02);
    o.noise_um = 0.0;
    const ProbeSimulation sim = simulate_probe(m, o);
    const ProbeSession& s = sim.session;
    REQUIRE(s.samples.size() == 24 * 5);
    EffectModel fx = m.effects;
    fx.linear_reference = Eigen::Vector3d::Zero();
    double worst = 0.0;
    for (const ProbeSample& x : s.samples) {
      ProbeTouch t;
      t.xyz = x.xyz, t.n = x.n, t.angles = x.angles_rad(), t.time = x.time;
      t.n_spindle = spindle_frame_direction(m.machine, t.angles, t.n);
      worst = std::max(
          worst, std::abs(touch_residual<double>(m.machine, m.errors, fx, m.effect_params.data(),
                                                 sim.sphere_actual, t, s.trigger_radius())));
    }
    INFO(name);
    CHECK(worst < 1e-9);  // the lobing shift is exact in the latched position (touch_model.hpp)
    // AR(1) noise from touch to touch: successive touches' noise is correlated as asked.
    o.noise_um = 1.0;
    o.ar1_rho = 0.9;
    o.pattern.poses_deg.resize(12);
    for (int k = 0; k < 30; ++k)
      o.pattern.poses_deg.push_back(o.pattern.poses_deg[static_cast<std::size_t>(k)]);
    const ProbeSession noisy = simulate_probe(m, o).session;
    o.noise_um = 0.0;
    const ProbeSession clean = simulate_probe(m, o).session;
    const Eigen::Index n = static_cast<Eigen::Index>(noisy.samples.size());
    Eigen::MatrixXd e(n, 3);  // one stream per coordinate, touches in time order
    for (Eigen::Index i = 0; i < n; ++i)
      e.row(i) = (noisy.samples[static_cast<std::size_t>(i)].xyz -
                  clean.samples[static_cast<std::size_t>(i)].xyz)
                     .transpose();
    const double lag1 =
        (e.topRows(n - 1).array() * e.bottomRows(n - 1).array()).sum() / e.squaredNorm();
    CHECK(lag1 > 0.75);
    CHECK(std::sqrt(e.squaredNorm() / static_cast<double>(e.size())) * 1e3 ==
          Approx(1.0).margin(0.4));
  }
}

TEST_CASE("the simulator refuses what it cannot simulate", "[probe]") {
  const MachineModel m = MachineModel::nominal(MachineType::AC_trt);
  ProbeSimOptions o;
  o.pattern = default_probe_pattern(m.machine);
  o.ar1_rho = 1.0;
  CHECK_THROWS_AS(simulate_probe(m, o), InvalidArgument);
  o.ar1_rho = 0.0;
  o.noise_um = -1.0;
  CHECK_THROWS_AS(simulate_probe(m, o), InvalidArgument);
  o.noise_um = 0.5;
  o.pattern.directions.push_back(Eigen::Vector3d::Zero());
  CHECK_THROWS_AS(simulate_probe(m, o), InvalidArgument);
  o.pattern.poses_deg.clear();
  CHECK_THROWS_AS(simulate_probe(m, o), InvalidArgument);
}
