// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/io/realtime_export.hpp"

#include "rotacal/core/error.hpp"
#include "rotacal/io/thermal_model.hpp"
#include "rotacal/realtime/blob.hpp"

namespace rotacal {

namespace {
realtime::Axis realtime_axis(const RotaryAxis& a) {
  realtime::Axis r;
  r.name = a.name;
  r.on_head = a.on_head;
  r.principal = a.principal;
  r.direction = a.direction;
  r.point = a.point;
  r.position_basis = a.position_basis;
  r.direction_basis = a.direction_basis;
  r.radial1 = a.radial1;
  r.radial2 = a.radial2;
  return r;
}

realtime::Model nominal_realtime_model(MachineType m) {
  const MachineDescription& d = m.description();
  realtime::Model out;
  for (int k = 0; k < 2; ++k) out.axes[k] = realtime_axis(d.axis(k));
  out.table_axes = static_cast<int>(d.table_axes.size());
  out.rot = m.rot_index();
  out.pivot_length = d.pivot_length;
  return out;
}
}  // namespace

realtime::Model realtime_model(MachineType m, const LocationErrors<double>& e,
                               const EffectModel& fx, const std::vector<double>& p,
                               const std::string& context) {
  if (static_cast<int>(fx.effects.size()) > realtime::kMaxEffects)
    throw InvalidArgument(context + ": " + std::to_string(fx.effects.size()) +
                          " effects, more than the real-time model holds (" +
                          std::to_string(realtime::kMaxEffects) + ")");
  if (static_cast<int>(p.size()) != fx.num_params())
    throw InvalidArgument(context + ": " + std::to_string(p.size()) + " effect parameters for " +
                          std::to_string(fx.num_params()) + " expected");
  if (fx.num_params() > realtime::kMaxParams)
    throw InvalidArgument(context + ": " + std::to_string(fx.num_params()) +
                          " effect parameters, more than the real-time model holds (" +
                          std::to_string(realtime::kMaxParams) + ")");
  realtime::Model out = nominal_realtime_model(m);
  out.errors = e;
  for (std::size_t i = 0; i < fx.effects.size(); ++i) {
    const Effect& f = fx.effects[i];
    if (!f.applies_to(m))
      throw InvalidArgument(context + ": effect " + f.id() + " does not exist on " + to_string(m));
    if (f.harmonic < 0 || f.harmonic > 255)
      throw InvalidArgument(context + ": effect " + f.id() + ": harmonic beyond 255");
    out.effects[i] = realtime::Term{f.kind, f.axis, f.harmonic, f.direction};
  }
  out.num_effects = static_cast<int>(fx.effects.size());
  for (std::size_t i = 0; i < p.size(); ++i) out.params[i] = p[i];
  out.num_params = static_cast<int>(p.size());
  out.linear_reference = fx.linear_reference.value_or(Eigen::Vector3d::Zero());
  return out;
}

realtime::Model realtime_model(const ModelFile& model, const std::string& context) {
  return realtime_model(model.machine, model.location_errors, model.effects, model.effect_params,
                        context);
}

realtime::Model realtime_model(const ThermalModel& model, const std::string& context) {
  if (model.lags.empty() || model.lags.size() > 2)
    throw InvalidArgument(context + ": " + std::to_string(model.lags.size()) +
                          " lags; the real-time model holds 1 or 2");
  realtime::Model out = realtime_model(model.machine, model.cold, EffectModel{}, {}, context);
  for (std::size_t l = 0; l < model.lags.size(); ++l)
    out.thermal_gain.col(static_cast<Eigen::Index>(l)) = model.lags[l].gains;
  return out;
}

std::uint64_t realtime_fingerprint(MachineType m) {
  return realtime::machine_fingerprint(nominal_realtime_model(m));
}

realtime::Model read_realtime_blob(const std::string& bytes, const MachineType* m,
                                   const std::string& source) {
  realtime::Model out;
  const realtime::LoadResult r =
      realtime::decode(bytes.data(), bytes.size(), m ? realtime_fingerprint(*m) : 0, out);
  if (!r.ok) {
    std::string what = std::string(r.field);
    if (r.index >= 0) what += "[" + std::to_string(r.index) + "]";
    what += std::string(": ") + r.reason;
    if (m && std::string(r.field) == "machine") what += " (expected " + to_string(*m) + ")";
    throw ParseError(source, 0, 0, what);
  }
  return out;
}

}  // namespace rotacal
