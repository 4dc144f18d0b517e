// SPDX-License-Identifier: BSD-3-Clause
// The catalogue of the circular-test diagnosis (diagnosis.hpp): its entries, their parameters
// with units, and the cause each one names.
#include "diagnosis_detail.hpp"
#include "rotacal/core/error.hpp"

namespace rotacal::circular_detail {

namespace {
const char* kAxes = "XYZ";
}  // namespace

std::string axis_name(int i) { return std::string(1, kAxes[i]); }

// Plausible sizes per unit, for visibility (see CircularDiagnosisOptions::min_visible_chi2).
double magnitude(const std::string& unit) {
  if (unit == "rad") return 50e-6;
  if (unit == "mm/mm") return 50e-6;
  if (unit == "s") return 1e-3;
  return 0.005;  // mm
}

}  // namespace rotacal::circular_detail

namespace rotacal {

using circular_detail::axis_name;

std::string CircularEffect::id() const {
  switch (kind) {
    case CircularEffectKind::squareness:
      return "squareness_" + to_string(plane);
    case CircularEffectKind::scale_mismatch:
      return "scale_mismatch_" + to_string(plane);
    case CircularEffectKind::straightness:
      return "straightness_" + axis_name(direction) + axis_name(axis);
    case CircularEffectKind::backlash:
      return "backlash_" + axis_name(axis);
    case CircularEffectKind::reversal_spike:
      return "reversal_spike_" + axis_name(axis);
    case CircularEffectKind::servo_mismatch:
      return "servo_mismatch_" + to_string(plane);
    case CircularEffectKind::cyclic_error:
      return "cyclic_error_" + axis_name(axis);
  }
  ROTACAL_ASSERT(false);
  return {};
}

CircularEffect CircularEffect::parse(const std::string& id) {
  for (const CircularEffect& e : circular_catalogue())
    if (e.id() == id) return e;
  std::string known;
  for (const CircularEffect& e : circular_catalogue())
    known += (known.empty() ? "" : ", ") + e.id();
  throw InvalidArgument("unknown circular-test effect '" + id + "' (known: " + known + ")");
}

std::vector<std::string> CircularEffect::param_names() const {
  switch (kind) {
    case CircularEffectKind::squareness:
      return {"s"};
    case CircularEffectKind::scale_mismatch:
      return {"dk"};
    case CircularEffectKind::straightness:
      return {"c2"};
    case CircularEffectKind::backlash:
      return {"b", "delay"};
    case CircularEffectKind::reversal_spike:
      return {"h", "tau", "delay"};
    case CircularEffectKind::servo_mismatch:
      return {"dtau"};
    case CircularEffectKind::cyclic_error:
      return {"c", "d"};
  }
  return {};
}

std::vector<std::string> CircularEffect::param_units() const {
  switch (kind) {
    case CircularEffectKind::squareness:
      return {"rad"};
    case CircularEffectKind::scale_mismatch:
      return {"mm/mm"};
    case CircularEffectKind::straightness:
      return {"mm"};
    case CircularEffectKind::backlash:
      return {"mm", "s"};
    case CircularEffectKind::reversal_spike:
      return {"mm", "s", "s"};
    case CircularEffectKind::servo_mismatch:
      return {"s"};
    case CircularEffectKind::cyclic_error:
      return {"mm", "mm"};
  }
  return {};
}

std::string CircularEffect::cause() const {
  const auto ax = plane_axes(plane);
  const std::string u = axis_name(ax[0]), v = axis_name(ax[1]);
  switch (kind) {
    case CircularEffectKind::squareness:
      return "axes " + u + " and " + v + " are not perpendicular (" + u + " moves by s per mm of " +
             v + "): an ellipse at 45 deg, the same in both directions";
    case CircularEffectKind::scale_mismatch:
      return "axes " + u + " and " + v +
             " scale differently (screw pitch error, encoder, thermal "
             "expansion of one axis): an ellipse along the axes";
    case CircularEffectKind::straightness:
      return "axis " + axis_name(axis) + " is not straight in " + axis_name(direction) +
             " (a bowed guideway, ISO 230-1 E_" + axis_name(direction) + axis_name(axis) + ")";
    case CircularEffectKind::backlash:
      return "lost motion of axis " + axis_name(axis) +
             " at reversal (screw or nut backlash, worn drive): a step at its reversal points, "
             "opposite in the two directions";
    case CircularEffectKind::reversal_spike:
      return "axis " + axis_name(axis) +
             " sticks when it reverses (friction, the servo's integral "
             "action catching up): an outward spike decaying after its reversal points";
    case CircularEffectKind::servo_mismatch:
      return "the position loops of " + u + " and " + v +
             " lag differently (unequal servo gains): a "
             "45 deg ellipse that tilts the other way when the direction reverses, growing with "
             "feed";
    case CircularEffectKind::cyclic_error:
      return "cyclic error of axis " + axis_name(axis) +
             " periodic with its screw lead (screw "
             "runout, thrust bearing, encoder interpolation)";
  }
  return {};
}

std::vector<CircularEffect> circular_catalogue() {
  std::vector<CircularEffect> out;
  const CircularPlane planes[] = {CircularPlane::XY, CircularPlane::YZ, CircularPlane::ZX};
  for (CircularEffectKind k : {CircularEffectKind::squareness, CircularEffectKind::scale_mismatch})
    for (CircularPlane p : planes) out.push_back({k, p, 0, 0});
  for (int A = 0; A < 3; ++A)
    for (int D = 0; D < 3; ++D)
      if (D != A) out.push_back({CircularEffectKind::straightness, CircularPlane::XY, A, D});
  for (CircularEffectKind k : {CircularEffectKind::backlash, CircularEffectKind::reversal_spike})
    for (int a = 0; a < 3; ++a) out.push_back({k, CircularPlane::XY, a, 0});
  for (CircularPlane p : planes) out.push_back({CircularEffectKind::servo_mismatch, p, 0, 0});
  for (int a = 0; a < 3; ++a)
    out.push_back({CircularEffectKind::cyclic_error, CircularPlane::XY, a, 0});
  return out;
}

}  // namespace rotacal
