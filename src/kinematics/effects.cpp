// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/kinematics/effects.hpp"

#include <algorithm>
#include <array>
#include <cctype>

namespace rotacal {

namespace {

struct KindInfo {
  EffectKind kind;
  const char* stem;   // id up to the axis
  bool rotary_axis;   // takes A/B/C
  bool tilt_only;     // only A or B
  bool linear_axis;   // takes X/Y/Z
  bool harmonic;      // has _hn (the parameter count: effect_num_params)
  const char* names;  // comma separated
  const char* units;
  const char* cause;
};

constexpr KindInfo kKindInfo[] = {
    {EffectKind::ballbar_length_offset, "ballbar_length_offset", false, false, false, false, "dL",
     "mm", "the calibrated ballbar length L0 is wrong"},
    {EffectKind::ballbar_thermal_drift, "ballbar_thermal_drift", false, false, false, false, "k",
     "mm/s", "the bar or the set-up grows with temperature during the test"},
    {EffectKind::tool_offset_Z, "tool_offset_Z", false, false, false, false, "d", "mm",
     "the tool-cup centre is not at the programmed tool length"},
    {EffectKind::rotary_zero_offset, "rotary_zero_offset", true, false, false, false, "eps", "rad",
     "the zero of the rotary axis is off"},
    {EffectKind::angular_positioning, "angular_positioning", true, false, false, true, "a,b",
     "rad,rad",
     "angular positioning error of the rotary axis (encoder eccentricity, worm or gear error)"},
    {EffectKind::radial_motion, "radial_motion", true, false, false, true, "a,b,c,d", "mm,mm,mm,mm",
     "radial error motion of the rotary axis (out-of-round bearing track)"},
    {EffectKind::axial_motion, "axial_motion", true, false, false, true, "a,b", "mm,mm",
     "axial error motion of the rotary axis (face runout)"},
    {EffectKind::tilt_motion, "tilt_motion", true, false, false, true, "a,b,c,d", "rad,rad,rad,rad",
     "tilt error motion of the rotary axis (wobble of the rotating table)"},
    {EffectKind::gravity_sag, "gravity_sag", true, true, false, false, "s", "mm",
     "the tilting table deflects under its own weight"},
    {EffectKind::coning, "coning", true, true, false, false, "k", "rad/rad",
     "the tilting axis' orientation changes in proportion to its angle (coning)"},
    {EffectKind::linear_squareness, "linear_squareness", false, false, true, false, "s", "rad",
     "two linear axes are out of square"},
    {EffectKind::linear_scale, "linear_scale", false, false, true, false, "k", "mm/mm",
     "linear positioning scale error"},
    {EffectKind::thermal_drift, "thermal_drift", false, false, true, false, "d", "mm/s",
     "the machine structure drifts while the test runs"},
    // tau = 300 s * exp(q): q is dimensionless (unit "1"), 0 a sensible start for a test of
    // minutes; the nonlinear refit moves it once d is non-zero.
    {EffectKind::thermal_warmup, "thermal_warmup", false, false, true, false, "d,ln_tau_300s",
     "mm,1", "the structure warms up towards a steady state"},
    {EffectKind::straightness, "straightness", false, false, true, false, "c2,c3,c4", "mm,mm,mm",
     "the linear axis is not straight (ISO 230-1 straightness error)"},
    {EffectKind::tool_offset, "tool_offset", false, false, true, false, "d", "mm",
     "the tool-side ball is off the spindle axis"},
    {EffectKind::rotary_backlash, "backlash", true, false, false, false, "b", "rad",
     "lost motion in the rotary axis' drive (backlash of the worm or gear, or wind-up): the "
     "axis trails by half of it in its direction of travel"},
    {EffectKind::servo_lag, "servo_lag", true, false, false, false, "tau", "s",
     "the rotary axis' position loop lags behind the linear axes' (unequal servo gains): the "
     "angle trails in proportion to the angular speed"},
    // tau_s = 0.05 s * exp(q): a few tens of ms, as friction at a reversal releases.
    {EffectKind::reversal_spike, "reversal_spike", true, false, false, false, "h,ln_tau_50ms",
     "rad,1",
     "the rotary axis sticks when it reverses (static friction) and catches up over a "
     "short time"},
    {EffectKind::stylus_radius_offset, "stylus_radius_offset", false, false, false, false, "d",
     "mm", "the stylus' effective radius differs from its calibration (touch probe)"},
    {EffectKind::probe_lobing, "probe_lobing", false, false, false, false, "lc,ls", "mm,mm",
     "the touch probe's pretravel depends on the direction of approach (three-lobed, as "
     "kinematic-seat probes are)"},
    {EffectKind::linear_pitch, "angular_error", false, false, true, false, "e1,e2", "rad,rad",
     "the linear axis' carriage pitches as it moves (ISO 230-1 angular error), seen through the "
     "tool's height"},
};

// info() is called for every effect of every sample inside the fits and simulators
// (EffectModel::offset, Effect::num_params): a table indexed by the kind, built at compile
// time, not a search.
constexpr std::size_t kKindSlots = 64;
constexpr std::array<const KindInfo*, kKindSlots> kByKind = [] {
  std::array<const KindInfo*, kKindSlots> t{};
  for (const KindInfo& i : kKindInfo) t[static_cast<std::size_t>(i.kind)] = &i;
  return t;
}();

const KindInfo& info(EffectKind k) {
  const auto slot = static_cast<std::size_t>(k);
  if (slot >= kKindSlots || kByKind[slot] == nullptr)
    throw Error("internal error: effect kind without catalogue entry");
  return *kByKind[slot];
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::size_t a = 0;
  for (std::size_t b; (b = s.find(',', a)) != std::string::npos; a = b + 1)
    out.push_back(s.substr(a, b - a));
  out.push_back(s.substr(a));
  return out;
}

const char* squareness_plane(char axis) { return axis == 'X' ? "XY" : axis == 'Y' ? "YZ" : "ZX"; }

}  // namespace

std::string Effect::id() const {
  if (!session.empty()) {
    Effect machine = *this;
    machine.session.clear();
    return session + ":" + machine.id();
  }
  const KindInfo& k = info(kind);
  std::string s = k.stem;
  if (kind == EffectKind::linear_squareness) return s + "_" + squareness_plane(axis);
  if (kind == EffectKind::straightness || kind == EffectKind::linear_pitch)
    return s + "_" + direction + axis;
  if (k.rotary_axis || k.linear_axis) s += std::string("_") + axis;
  if (k.harmonic) s += "_h" + std::to_string(harmonic);
  return s;
}

Effect Effect::parse(const std::string& id) {
  const std::size_t colon = id.rfind(':');
  if (colon != std::string::npos) {  // "session:id" (Effect::session)
    Effect f = parse(id.substr(colon + 1));
    f.session = id.substr(0, colon);
    if (f.session.empty()) throw InvalidArgument("effect id '" + id + "': no session before ':'");
    return f;
  }
  for (const KindInfo& k : kKindInfo) {
    const std::string stem = k.stem;
    if (id.compare(0, stem.size(), stem) != 0) continue;
    std::string rest = id.substr(stem.size());
    Effect f;
    f.kind = k.kind;
    if (!k.rotary_axis && !k.linear_axis) {
      if (rest.empty()) return f;
      continue;
    }
    if (k.kind == EffectKind::straightness) {  // straightness_DA, D != A
      if (rest.size() == 3 && rest[0] == '_' &&
          std::string("XYZ").find(rest[1]) != std::string::npos &&
          std::string("XYZ").find(rest[2]) != std::string::npos && rest[1] != rest[2]) {
        f.axis = rest[2];
        f.direction = rest[1];
        return f;
      }
      break;
    }
    if (k.kind == EffectKind::linear_pitch) {  // angular_error_BX, angular_error_AY
      if (rest == "_BX" || rest == "_AY") {
        f.axis = rest[2];
        f.direction = rest[1];
        return f;
      }
      break;
    }
    if (k.kind == EffectKind::tool_offset) {  // X or Y (tool_offset_Z is its own entry)
      if (rest == "_X" || rest == "_Y") {
        f.axis = rest[1];
        return f;
      }
      break;
    }
    if (k.kind == EffectKind::linear_squareness) {
      for (char a : {'X', 'Y', 'Z'})
        if (rest == std::string("_") + squareness_plane(a)) return Effect{k.kind, a, 0};
      break;
    }
    if (rest.size() < 2 || rest[0] != '_') break;
    const char a = rest[1];
    const bool ok_axis = k.rotary_axis
                             ? (a == 'A' || a == 'B' || a == 'C') && !(k.tilt_only && a == 'C')
                             : (a == 'X' || a == 'Y' || a == 'Z');
    if (!ok_axis) break;
    f.axis = a;
    rest = rest.substr(2);
    if (!k.harmonic) {
      if (rest.empty()) return f;
      break;
    }
    if (rest.size() < 3 || rest.compare(0, 2, "_h") != 0) break;
    const std::string n = rest.substr(2);
    if (n.empty() || n.size() > 2 || !std::all_of(n.begin(), n.end(), ::isdigit)) break;
    f.harmonic = std::stoi(n);
    if (f.harmonic < 1 || (k.kind == EffectKind::radial_motion && f.harmonic < 2)) break;
    return f;
  }
  throw InvalidArgument("'" + id +
                        "' is not an effect id of the catalogue (shared/spec/effects.md)");
}

int Effect::num_params() const { return effect_num_params(kind); }
std::vector<std::string> Effect::param_names() const { return split(info(kind).names); }
std::vector<std::string> Effect::param_units() const { return split(info(kind).units); }
std::string Effect::cause() const { return info(kind).cause; }

bool Effect::depends_on_motion() const { return effect_depends_on_motion(kind); }

bool Effect::is_harmonic() const { return info(kind).harmonic; }

bool Effect::applies_to(MachineType m) const {
  const KindInfo& k = info(kind);
  if (!k.rotary_axis) return true;
  // Tilt-only effects (sag, coning) belong to the tilt axis, on the table or in the head.
  return k.tilt_only ? axis == tilt_axis_letter(m)
                     : (axis == tilt_axis_letter(m) || axis == rot_axis_letter(m));
}

std::vector<Effect> effect_catalogue(MachineType m, int max_harmonic) {
  std::vector<Effect> out;
  const char T = tilt_axis_letter(m), C = rot_axis_letter(m);
  for (const KindInfo& k : kKindInfo) {
    if (k.kind == EffectKind::stylus_radius_offset || k.kind == EffectKind::probe_lobing) continue;
    if (k.kind == EffectKind::straightness) {
      for (char a : {'X', 'Y', 'Z'})
        for (char d : {'X', 'Y', 'Z'})
          if (a != d) out.push_back({k.kind, a, 0, d});
    } else if (k.kind == EffectKind::linear_pitch) {
      out.push_back({k.kind, 'X', 0, 'B'});
      out.push_back({k.kind, 'Y', 0, 'A'});
    } else if (k.kind == EffectKind::tool_offset) {
      for (char a : {'X', 'Y'}) out.push_back({k.kind, a, 0});
    } else if (k.linear_axis) {
      for (char a : {'X', 'Y', 'Z'}) out.push_back({k.kind, a, 0});
    } else if (k.rotary_axis) {
      for (char a : {T, C}) {
        if (k.tilt_only && a != T) continue;
        if (!k.harmonic) {
          out.push_back({k.kind, a, 0});
          continue;
        }
        for (int n = k.kind == EffectKind::radial_motion ? 2 : 1; n <= max_harmonic; ++n)
          out.push_back({k.kind, a, n});
      }
    } else {
      out.push_back({k.kind, 0, 0});
    }
  }
  return out;
}

int EffectModel::num_params() const {
  int n = 0;
  for (const Effect& f : effects) n += effect_num_params(f.kind);
  return n;
}

int EffectModel::offset(std::size_t i) const {
  int n = 0;
  for (std::size_t k = 0; k < i; ++k) n += effect_num_params(effects[k].kind);
  return n;
}

std::vector<std::string> EffectModel::param_labels() const {
  std::vector<std::string> out;
  for (const Effect& f : effects)
    for (const std::string& n : f.param_names()) out.push_back(f.id() + "." + n);
  return out;
}

}  // namespace rotacal
