// SPDX-License-Identifier: BSD-3-Clause
// The part of the controller exports that every controller shares (shared.hpp).
#include "shared.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

namespace rotacal::export_detail {

LineMaps line_maps(MachineType m) {
  LineMaps L;
  L.tilt = m == MachineType::AC_trt ? 'A' : 'B';
  const LocationErrors<double> none;
  const AxisLine<double> T0 = tilt_axis_line(m, none), C0 = c_axis_line(m, none);
  L.tilt_axis = T0.direction;
  L.c_axis = C0.direction;
  for (int i = 0; i < 8; ++i) {
    LocationErrors<double> unit;
    unit.v[i] = 1.0;
    const AxisLine<double> T = tilt_axis_line(m, unit), C = c_axis_line(m, unit);
    L.tilt_point.col(i) = T.point - T0.point;
    L.tilt_dir.col(i) = T.direction - T0.direction;
    L.c_point.col(i) = C.point - C0.point;
    L.c_dir.col(i) = C.direction - C0.direction;
  }
  return L;
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  std::string s = buf;
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);  // no "-0.000"
  return s;
}

namespace {

std::string utc_now() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// "E_Y0A - E_Y0C" from a coefficient row.
std::string from_text(const Row& c, MachineType m) {
  const auto& names = location_error_names(m);
  std::string s;
  for (int i = 0; i < 8; ++i) {
    if (c[i] == 0.0) continue;
    const std::string sign = c[i] > 0 ? (s.empty() ? "" : " + ") : (s.empty() ? "-" : " - ");
    s += sign + (std::abs(c[i]) == 1.0 ? "" : fixed(std::abs(c[i]), 3) + " ") +
         names[static_cast<std::size_t>(i)];
  }
  return s;
}

// The errors as used: an unobservable one is not applied (its parameters keep their value).
Eigen::Matrix<double, 8, 1> applied(const ExportInput& in) {
  Eigen::Matrix<double, 8, 1> e = in.errors.v;
  for (int i = 0; i < 8; ++i)
    if (!in.observable[static_cast<std::size_t>(i)]) e[i] = 0.0;
  return e;
}

}  // namespace

double current_of(const ExportOptions& o, const std::string& name, double fallback) {
  const auto it = o.current.find(name);
  return it == o.current.end() ? fallback : it->second;
}

ControllerValue value_of(const Param& p, double current, const ExportInput& in) {
  Row c = p.coef;
  for (int i = 0; i < 8; ++i)
    if (!in.observable[static_cast<std::size_t>(i)]) c[i] = 0.0;
  ControllerValue v;
  v.name = p.name;
  v.unit = p.unit;
  v.current = current;
  v.corrected = current + p.scale * (c * applied(in))(0, 0);
  v.std = std::abs(p.scale) * std::sqrt(std::max(0.0, (c * in.covariance * c.transpose())(0, 0)));
  v.from = from_text(p.coef, in.machine);
  return v;
}

AxisVector corrected_axis(const Eigen::Vector3d& current_raw, const Eigen::Vector3d& nominal,
                          const Map3& dn, const ExportInput& in, const std::string& what,
                          double default_sense) {
  AxisVector a;
  a.current = current_raw.norm() > 0 ? current_raw : Eigen::Vector3d(default_sense * nominal);
  const Eigen::Vector3d u = a.current.normalized();
  const double cosine = u.dot(nominal);
  if (std::abs(cosine) < std::cos(1.0 * M_PI / 180.0))
    throw InvalidArgument(what + ": the current axis vector (" + fixed(a.current.x(), 6) + ", " +
                          fixed(a.current.y(), 6) + ", " + fixed(a.current.z(), 6) +
                          ") is more than 1 deg from the machine's nominal axis; "
                          "the export corrects a kinematics of this machine");
  const double s = cosine > 0 ? 1.0 : -1.0;
  Map3 c = s * dn;
  for (int i = 0; i < 8; ++i)
    if (!in.observable[static_cast<std::size_t>(i)]) c.col(i).setZero();
  a.coef = c;
  a.corrected = (u + c * in.errors.v).normalized();
  return a;
}

ControllerValue vector_component(const std::string& name, const AxisVector& a, int k,
                                 const ExportInput& in, const Map3& dn) {
  ControllerValue v;
  v.name = name;
  v.unit = "1";
  v.current = a.current[k];
  v.corrected = a.corrected[k];
  const Row c = a.coef.row(k);
  v.std = std::sqrt(std::max(0.0, (c * in.covariance * c.transpose())(0, 0)));
  v.from = from_text(dn.row(k), in.machine);
  return v;
}

ControllerExport new_export(Controller c, const std::string& kinematics,
                            const std::string& file_kind, const ExportOptions& o) {
  ControllerExport ex;
  ex.controller = c;
  ex.kinematics = kinematics;
  ex.file_kind = file_kind;
  ex.current_given = o.current_given;
  return ex;
}

void header(Writer& w, const ControllerExport& ex, const ExportInput& in, const ExportOptions& o,
            const std::string& title) {
  w.line("rotacal export: " + title);
  w.line("model: " + (in.model_path.empty() ? std::string("(not named)") : in.model_path) +
         (in.source.empty() ? "" : "; identified from " + in.source));
  w.line("written: " + (o.generated_at.empty() ? utc_now() : o.generated_at));
  w.line(ex.current_given
             ? "current values: as given (the values active while the test ran)"
             : "current values: NOT GIVEN - zero offsets assumed, so each value below is the "
               "correction itself; add it to the controller's value");
  if (!in.full_covariance)
    w.line("1-sigma: from each error's own std (the model holds no covariance)");
  w.line();
  w.line("parameter | current | corrected | 1-sigma | unit | from");
  for (const ControllerValue& v : ex.values) {
    const int d = v.unit == "1" ? 9 : v.unit == "0.1 um" ? 1 : 6;
    w.line(v.name + " | " + fixed(v.current, d) + " | " + fixed(v.corrected, d) + " | " +
           fixed(v.std, d + 1) + " | " + v.unit + " | " + (v.from.empty() ? "-" : v.from));
  }
  w.line();
  for (std::size_t i = 0; i < ex.errors.size(); ++i) {
    const ErrorDisposition& e = ex.errors[i];
    const bool angle = location_error_is_angle(static_cast<int>(i));
    const std::string val = e.observable ? fixed(e.value * (angle ? 1e6 : 1e3), 2) + " +- " +
                                               fixed(e.std * (angle ? 1e6 : 1e3), 2) +
                                               (angle ? " urad" : " um")
                                         : "not determined by the data";
    w.line(e.name + " = " + val + ": " + (e.held ? "held in " : "NOT HELD: ") + e.where);
  }
  if (ex.not_held.v.cwiseAbs().maxCoeff() > 0)
    w.line(
        "Errors not held remain: apply them as NC compensation (rotacal compensate --model ...).");
  w.line();
}

void dispositions(ControllerExport& ex, const ExportInput& in,
                  const std::array<std::string, 8>& where, const std::array<bool, 8>& held) {
  const auto& names = location_error_names(in.machine);
  for (int i = 0; i < 8; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ErrorDisposition d;
    d.name = names[k];
    d.value = in.errors.v[i];
    d.std = std::sqrt(std::max(0.0, in.covariance(i, i)));
    d.observable = in.observable[k];
    d.held = held[k] && d.observable;
    d.where = !d.observable ? "not determined by the data: the parameters keep their current value"
                            : where[k];
    if (!held[k] && d.observable) ex.not_held.v[i] = in.errors.v[i];
    ex.errors.push_back(d);
  }
}

}  // namespace rotacal::export_detail
