// SPDX-License-Identifier: BSD-3-Clause
// The touch-probe problem: layout, touches and the residual model (probe/problem.hpp).
#include "rotacal/probe/problem.hpp"

namespace rotacal {

std::vector<Effect> probe_effect_catalogue(MachineType m, int max_harmonic) {
  std::vector<Effect> out = effect_catalogue(m, max_harmonic);
  out.push_back(Effect::parse("stylus_radius_offset"));
  out.push_back(Effect::parse("probe_lobing"));
  return out;
}

ProbeParameterLayout ProbeParameterLayout::make(MachineType m, const EffectModel& fx) {
  ProbeParameterLayout L;
  L.errors = add_location_errors(L.all, m);
  L.tool_length = L.all.add(
      "tool_length",
      m.has_head() ? std::vector<std::string>{"tool_offset_Z"} : std::vector<std::string>{},
      {"mm"});
  L.sphere = L.all.add("sphere", {"sphere.x", "sphere.y", "sphere.z"}, {"mm"});
  L.effects = add_effects(L.all, fx);
  return L;
}

std::vector<ProbeTouch> probe_touches(const ProbeSession& session) {
  std::vector<ProbeTouch> out;
  out.reserve(session.samples.size());
  for (const ProbeSample& s : session.samples) {
    ProbeTouch t;
    t.xyz = s.xyz;
    t.n = s.n.normalized();
    t.angles = s.angles_rad();
    t.n_spindle = spindle_frame_direction(session.machine, t.angles, t.n);
    t.time = s.time;
    out.push_back(t);
  }
  return out;
}

ProbeProblem::ProbeProblem(const ProbeSession& session, const EffectModel& effects)
    : machine_(session.machine),
      fx_(centred_on(effects, session.samples)),
      layout_(ProbeParameterLayout::make(session.machine, fx_)),
      sphere_nominal_(session.sphere),
      radius_(session.trigger_radius()),
      touches_(probe_touches(session)) {
  if (touches_.empty()) throw InvalidArgument("probe problem: the session has no touches");
  for (const Effect& f : fx_.effects)
    if (!f.applies_to(machine_))
      throw InvalidArgument("probe problem: effect " + f.id() + " does not exist on " +
                            to_string(machine_));
  for (const ProbeSample& s : session.samples) {
    groups_.push_back("touches");
    times_.push_back(s.time);
  }
}

std::vector<FitParameter> ProbeProblem::parameters() const {
  std::vector<FitParameter> out;
  const std::vector<std::string> names = layout_.all.names(), units = layout_.all.units();
  for (Eigen::Index j = 0; j < layout_.size(); ++j) {
    const std::size_t k = static_cast<std::size_t>(j);
    FitParameter p{names[k], units[k], 0.0};
    if (layout_.sphere.contains(j)) p.start = sphere_nominal_[j - layout_.sphere.offset];
    if (layout_.effects.contains(j)) p.yields = true;  // catalogue effects yield to the baseline
    out.push_back(p);
  }
  return out;
}

void ProbeProblem::evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                            Eigen::MatrixXd* J) const {
  const ProbeParameterLayout& L = layout_;
  const auto one = [&](Eigen::Index i, const auto* p, auto* out) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
    const LocationErrors<T> e = LocationErrors<T>::from_ptr(L.errors.ptr(p));
    const T* q = L.sphere.ptr(p);
    const T tool = L.tool_length.empty() ? T(0) : T(-L.tool_length.ptr(p)[0]);
    out[0] = touch_residual<T>(machine_, e, fx_, L.effects.ptr(p), Vec3<T>(q[0], q[1], q[2]),
                               touches_[static_cast<std::size_t>(i)], radius_, tool);
  };
  evaluate_with_jets(one, num_residuals(), 1, x, r, J);
}

Eigen::VectorXd ProbeProblem::residuals(const Eigen::VectorXd& x) const {
  Eigen::VectorXd r(num_residuals());
  evaluate(x, r, nullptr);
  return r;
}

}  // namespace rotacal
