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
  L.errors = {0, LocationErrors<double>::kSize};
  L.tool_length = {L.errors.offset + L.errors.size, m.has_head() ? 1 : 0};
  L.sphere = {L.tool_length.offset + L.tool_length.size, 3};
  L.effects = {L.sphere.offset + L.sphere.size, fx.num_params()};
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
    : machine_(session.machine), fx_(centred_on(effects, session.samples)),
      layout_(ProbeParameterLayout::make(session.machine, fx_)), sphere_nominal_(session.sphere),
      radius_(session.trigger_radius()), touches_(probe_touches(session)) {
  if (touches_.empty()) throw InvalidArgument("probe problem: the session has no touches");
  for (const Effect& f : fx_.effects)
    if (!f.applies_to(machine_))
      throw InvalidArgument("probe problem: effect " + f.id() + " does not exist on " + to_string(machine_));
  for (const ProbeSample& s : session.samples) {
    groups_.push_back("touches");
    times_.push_back(s.time);
  }
}

std::vector<FitParameter> ProbeProblem::parameters() const {
  std::vector<FitParameter> out;
  const auto& names = location_error_names(machine_);
  for (int k = 0; k < layout_.errors.size; ++k)
    out.push_back({names[static_cast<std::size_t>(k)], location_error_is_angle(k) ? "rad" : "mm", 0.0});
  if (layout_.tool_length.size) out.push_back({"tool_offset_Z", "mm", 0.0});
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) out.push_back({std::string("sphere.") + axes[k], "mm", sphere_nominal_[k]});
  for (const Effect& f : fx_.effects) {
    const auto pn = f.param_names(), pu = f.param_units();
    for (std::size_t k = 0; k < pn.size(); ++k)
      out.push_back({f.id() + (pn.size() > 1 ? "." + pn[k] : ""), pu[k], 0.0, 0.0, false, true});
  }
  return out;
}

void ProbeProblem::evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r, Eigen::MatrixXd* J) const {
  const ProbeParameterLayout& L = layout_;
  const auto one = [&](Eigen::Index i, const auto* p, auto* out) {
    using T = std::remove_const_t<std::remove_pointer_t<decltype(p)>>;
    const LocationErrors<T> e = LocationErrors<T>::from_ptr(ProbeParameterLayout::at(L.errors, p));
    const T* q = ProbeParameterLayout::at(L.sphere, p);
    const T tool = L.tool_length.size ? T(-ProbeParameterLayout::at(L.tool_length, p)[0]) : T(0);
    out[0] = touch_residual<T>(machine_, e, fx_, ProbeParameterLayout::at(L.effects, p), Vec3<T>(q[0], q[1], q[2]),
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
