// SPDX-License-Identifier: BSD-3-Clause
// The errors that move with a rotary axis, from an R-test map or from catalogue effects, each
// evaluated by the model's own code (rtest/predict.hpp, kinematics/effects.hpp).
#include "rotacal/compensation/axis_errors.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <memory>

#include "rotacal/core/error.hpp"
#include "rotacal/kinematics/effects.hpp"
#include "rotacal/rtest/error_model.hpp"
#include "rotacal/rtest/predict.hpp"

namespace rotacal {

namespace axis_errors_detail {

// Delta (machine frame, about the origin) as the terms about the axis' nominal point.
AngleMapTerms terms_of(const Pose<double>& delta, const RotaryAxis& ax) {
  const Pose<double> at_point{delta.R, delta * ax.point - ax.point};
  AngleMapTerms t;
  t.head<6>() = oyama_errors_of(at_point);
  // A principal axis: its own Euler component (the R-test map's gamma or beta itself, no
  // second-order part of the other two); a nutating one: the rotation vector along it.
  if (ax.principal >= 0) {
    t[6] = t[3 + ax.principal] * (ax.direction[ax.principal] < 0 ? -1.0 : 1.0);
  } else {
    const Eigen::AngleAxisd r(delta.R);
    t[6] = r.angle() * r.axis().dot(ax.direction);
  }
  return t;
}

AxisErrorFunction named(const MachineType& m, int k) {
  AxisErrorFunction f;
  f.chain_index = k;
  f.axis = m.description().axis(k).name;
  const std::string a(1, f.axis);
  f.names = {"E_X" + a, "E_Y" + a, "E_Z" + a, "E_A" + a, "E_B" + a, "E_C" + a, "positioning_" + a};
  f.units = {"mm", "mm", "mm", "rad", "rad", "rad", "rad"};
  return f;
}

// The stages of chain axis k alone (effects.hpp's walk), with nominal lines: its error motion,
// its rotation at the actual angle, its coning, and the machine-frame translations (gravity
// sag, which with the other axis at 0 is this axis' own).
struct OneAxisAccumulator {
  int k = 0;
  Pose<double> T;
  void rigid(const Pose<double>& P, int kk, RigidStage) {
    if (kk == k) T = P * T;
  }
  void about_line(const AxisLine<double>& L, double a, int kk) {
    if (kk == k) T = rotation_about_line(L.point, L.direction, a) * T;
  }
  void translate(const Eigen::Vector3d& d) { T.t += d; }
};

std::vector<AxisErrorFunction> effect_functions(const ModelFile& model) {
  const MachineType m = model.machine;
  auto fx = std::make_shared<const EffectModel>(model.effects);
  auto p = std::make_shared<const std::vector<double>>(model.effect_params);
  std::vector<AxisErrorFunction> out;
  const int n_table = static_cast<int>(m.description().table_axes.size());
  for (int k = 0; k < n_table; ++k) {
    AxisErrorFunction f = named(m, k);
    for (const Effect& e : fx->effects) {
      if (e.axis != f.axis) continue;
      if (e.depends_on_motion())
        f.notes.push_back(e.id() + ": depends on the motion, not on the angle; not in the map");
      else if (e.kind == EffectKind::rotary_zero_offset ||
               e.kind == EffectKind::angular_positioning || e.kind == EffectKind::radial_motion ||
               e.kind == EffectKind::axial_motion || e.kind == EffectKind::tilt_motion ||
               e.kind == EffectKind::gravity_sag || e.kind == EffectKind::coning)
        f.sources.push_back(e.id());
    }
    f.evaluate = [m, fx, p, k](double angle) {
      RotaryAngles<double> cmd;
      (k == m.rot_index() ? cmd.rot : cmd.tilt) = angle;
      OneAxisAccumulator acc{k, {}};
      const LocationErrors<double> nominal;  // zero: the kinematic parameters hold them
      walk_table_stages(m, nominal, *fx, p->empty() ? nullptr : p->data(), cmd, 0.0, RotaryMotion{},
                        acc);
      const RotaryAxis& ax = m.description().axis(k);
      const Pose<double> ideal = rotation_about_line(ax.point, ax.direction, angle);
      return terms_of(acc.T * ideal.inverse(), ax);
    };
    out.push_back(std::move(f));
  }
  return out;
}

// The R-test joint model of the file's maps, its location errors and tool_offset_Z at 0 (the
// kinematic parameters hold them).
RtestJointModel rtest_maps(const ModelFile& model, const std::string& source) {
  const nlohmann::ordered_json& d = model.document;
  const nlohmann::ordered_json& b = d.at("basis");
  RtestJointModel named_model;
  named_model.machine = model.machine;
  named_model.basis = RtestBasis{b.at("b_degree").get<int>(), b.at("c_harmonics").get<int>(),
                                 b.at("c_b_degree").get<int>(), b.at("gamma_cb").get<bool>()}
                          .for_machine(model.machine);
  const std::vector<std::string> names = named_model.parameter_names();
  const int nl = rtest_num_location_parameters(model.machine);
  Eigen::VectorXd params = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(names.size()));
  const nlohmann::ordered_json& mc = d.at("map_coefficients");
  for (std::size_t j = static_cast<std::size_t>(nl); j < names.size(); ++j) {
    if (!mc.contains(names[j]))
      throw InvalidArgument(source + ": map_coefficients: no " + names[j] +
                            ", which the basis names");
    const nlohmann::ordered_json& e = mc[names[j]];
    const nlohmann::ordered_json& v = e.is_object() ? e.at("value") : e;
    params[static_cast<Eigen::Index>(j)] = v.is_number() ? v.get<double>() : 0.0;
  }
  const auto n = params.size();
  return make_rtest_joint_model(model.machine, named_model.basis, params,
                                Eigen::MatrixXd::Zero(n, n),
                                std::vector<bool>(static_cast<std::size_t>(n), true));
}

std::vector<AxisErrorFunction> rtest_functions(const ModelFile& model, const std::string& source) {
  const MachineType m = model.machine;
  auto rm = std::make_shared<const RtestJointModel>(rtest_maps(model, source));
  const auto maps = rtest_map_names(m);
  const int n_table = static_cast<int>(m.description().table_axes.size());
  std::vector<AxisErrorFunction> out;
  for (int k = 0; k < n_table; ++k) {
    AxisErrorFunction f = named(m, k);
    const bool rot = k == m.rot_index();
    const std::string map = maps[rot ? 1 : 0];
    for (const std::string& name : rm->parameter_names())
      if (name.find("_" + map + ".") != std::string::npos) f.sources.push_back(name);
    if (rot && rm->basis.c_b_degree > 0 && m.description().table_axes.size() == 2)
      f.notes.push_back("the " + map + " map at tilt 0: its terms in the tilt angle are left out");
    if (rot && !rm->basis.gamma_cb)
      f.notes.push_back("the basis has no gamma term: the R-test did not give " +
                        std::string(1, f.axis) + "'s positioning error");
    f.evaluate = [rm, m, k, rot](double angle) {
      const AxisErrors<double> w = rot ? rm->w_CB(0.0, angle) : rm->w_BY(angle);
      return terms_of(oyama_error_pose(w), m.description().axis(k));
    };
    out.push_back(std::move(f));
  }
  return out;
}

}  // namespace axis_errors_detail

using axis_errors_detail::effect_functions;
using axis_errors_detail::rtest_functions;

std::vector<AxisErrorFunction> axis_error_functions(const ModelFile& model,
                                                    const std::string& source) {
  std::vector<AxisErrorFunction> out =
      model.kind == "rtest-joint" ? rtest_functions(model, source) : effect_functions(model);
  for (const RotaryAxis& h : model.machine.description().head_axes)
    for (AxisErrorFunction& f : out)
      f.notes.push_back(std::string("head axis ") + h.name +
                        ": no angle map (the maps cover the table's axes)");
  return out;
}

}  // namespace rotacal
