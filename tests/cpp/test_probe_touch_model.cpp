// SPDX-License-Identifier: BSD-3-Clause
// The touch model (probe/touch_model.hpp): an ideal touch has a zero residual, the probe's two
// effects act as effects.md says, and Jets of the one templated formula agree with central
// differences of its double evaluation.
#include <ceres/jet.h>

#include <catch2/catch.hpp>

#include "rotacal/probe/touch_model.hpp"

using namespace rotacal;

namespace {
constexpr double kRadius = 15.5;

EffectModel probe_effects() {
  return EffectModel{{Effect::parse("stylus_radius_offset"), Effect::parse("probe_lobing"),
                      Effect::parse("angular_positioning_C_h1"), Effect::parse("gravity_sag_A")},
                     std::nullopt};
}

ProbeTouch ideal_touch(MachineType m, const Eigen::Vector3d& q, const RotaryAngles<double>& a,
                       Eigen::Vector3d n) {
  ProbeTouch t;
  t.n = n.normalized();
  t.angles = a;
  t.n_spindle = spindle_frame_direction(m, a, t.n);
  t.xyz = inverse(m, LocationErrors<double>(), a, q).xyz - kRadius * t.n;
  return t;
}
}  // namespace

TEST_CASE("an ideal touch on the nominal machine has a zero residual", "[probe]") {
  for (const char* name : {"AC-trt", "BC-trt", "B-head-C-table", "AC-head"}) {
    const MachineType m = parse_machine_type(name);
    const Eigen::Vector3d q(150, 20, 80);
    for (const Eigen::Vector3d& n : {Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(-0.8, 0.3, -0.5)}) {
      const ProbeTouch t = ideal_touch(m, q, {0.4, -1.1}, n);
      const double r = touch_residual<double>(m, LocationErrors<double>(), EffectModel{}, nullptr,
                                              q, t, kRadius);
      CHECK(std::abs(r) < 1e-10);
    }
  }
}

TEST_CASE("stylus_radius_offset and probe_lobing act as effects.md says", "[probe]") {
  const MachineType m = MachineType::AC_trt;
  const Eigen::Vector3d q(150, 0, 80);
  const double s = 0.5, c = std::sqrt(3.0) / 2.0;
  const ProbeTouch t = ideal_touch(m, q, {0.0, 0.0}, Eigen::Vector3d(-c, 0, -s));
  const EffectModel fx{{Effect::parse("stylus_radius_offset"), Effect::parse("probe_lobing")},
                       std::nullopt};
  const double d = 2e-3, lc = 1e-3, ls = 0.7e-3;
  // The trigger distance grows by d: an ideal touch then reads d short.
  const std::vector<double> stylus{d, 0.0, 0.0};
  CHECK(touch_residual<double>(m, LocationErrors<double>(), fx, stylus.data(), q, t, kRadius) ==
        Approx(-d).margin(1e-12));
  // phi = atan2(0, -c) = pi: cos 3 phi = -1, sin 3 phi = 0, sqrt(1 - n_z^2) = c, so the latched
  // position moved by -lc c along n; the model takes it back.
  const std::vector<double> lobe{0.0, lc, ls};
  const std::vector<double> none(3, 0.0);
  const Eigen::Vector3d off0 =
      touch_offset<double>(m, LocationErrors<double>(), fx, none.data(), q, t);
  const Eigen::Vector3d off =
      touch_offset<double>(m, LocationErrors<double>(), fx, lobe.data(), q, t);
  CHECK((off - off0 - lc * c * t.n).norm() < 1e-12);
  // Along the spindle axis there is no lobing.
  const ProbeTouch top = ideal_touch(m, q, {0.0, 0.0}, Eigen::Vector3d(0, 0, -1));
  CHECK(lobing_shift<double>(fx, lobe.data(), top.n_spindle) == 0.0);
  // The three lobes: a turn of 120 deg about the spindle gives the same shift.
  const Eigen::Vector3d n1(0.6, 0.3, -0.74),
      n2 = Eigen::AngleAxisd(2 * M_PI / 3, Eigen::Vector3d::UnitZ()) * n1;
  CHECK(lobing_shift<double>(fx, lobe.data(), n1.normalized()) ==
        Approx(lobing_shift<double>(fx, lobe.data(), n2.normalized())).margin(1e-15));
}

TEST_CASE("Jets of the touch residual agree with central differences", "[probe]") {
  using Jet = ceres::Jet<double, 18>;
  for (const char* name : {"AC-trt", "B-head-C-table"}) {
    const MachineType m = parse_machine_type(name);
    const EffectModel fx = probe_effects();
    REQUIRE(8 + 3 + 1 + fx.num_params() == 18);
    Eigen::VectorXd x(8 + 3 + 1 + fx.num_params());
    x << 0.02, -0.01, 3e-5, -2e-5, 0.03, 0.01, 1e-5, 4e-5, 150.01, 0.02, 79.99, 0.004, 1e-3, 0.8e-3,
        -0.5e-3, 2e-5, -1e-5, 3e-3;
    ProbeTouch t =
        ideal_touch(m, Eigen::Vector3d(150, 0, 80), {0.5, 0.9}, Eigen::Vector3d(0.3, -0.7, -0.6));
    t.time = 30.0;
    auto f = [&](const auto* p) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
      return touch_residual<T>(m, LocationErrors<T>::from_ptr(p), fx, p + 12,
                               Vec3<T>(p[8], p[9], p[10]), t, kRadius, T(p[11]));
    };
    std::vector<Jet> xj(static_cast<std::size_t>(x.size()));
    for (Eigen::Index k = 0; k < x.size(); ++k)
      xj[static_cast<std::size_t>(k)] = Jet(x[k], static_cast<int>(k));
    const Jet r = f(xj.data());
    CHECK(r.a == Approx(f(x.data())).margin(1e-15));
    for (Eigen::Index k = 0; k < x.size(); ++k) {
      const double h = std::max(1e-7, 1e-7 * std::abs(x[k]));
      Eigen::VectorXd xp = x, xm = x;
      xp[k] += h, xm[k] -= h;
      const double fd = (f(xp.data()) - f(xm.data())) / (2 * h);
      INFO(name << " parameter " << k);
      CHECK(r.v[k] == Approx(fd).margin(1e-6 * (1 + std::abs(fd))));
    }
  }
}
