// SPDX-License-Identifier: BSD-3-Clause
// rotacal-model/1 files: strict JSON (nlohmann), validated member by member, versioned.
#include "rotacal/io/model_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <set>

#include "model_checks.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/core/json_text.hpp"
#include "rotacal/io/fitted_model.hpp"
#include "rotacal/io/thermal_model.hpp"

namespace rotacal {

namespace {

using json = nlohmann::ordered_json;
using model_checks::bad;
using model_checks::estimate;
using model_checks::member;
using model_checks::object_member;
using model_checks::shown;

const std::set<std::string> kKinds = {"ballbar", "rtest-joint", "rtest-diagnosis",
                                      "probe",   "multi",       "thermal"};

// Reads `rotacal-model/M` or `rotacal-model/M.N`; refuses another major version by name.
int format_minor(const json& doc, const std::string& source) {
  const auto it = doc.find("format");
  if (it == doc.end() || !it->is_string())
    bad(source, "format", "missing: not a rotacal-model file");
  const std::string f = it->get<std::string>();
  const std::string prefix = "rotacal-model/";
  if (f.rfind(prefix, 0) != 0) bad(source, "format", shown(*it) + " is not a rotacal-model file");
  const std::string ver = f.substr(prefix.size());
  int major = -1, minor = 0;
  const std::size_t dot = ver.find('.');
  try {
    std::size_t used = 0;
    major = std::stoi(ver.substr(0, dot), &used);
    if (used != ver.substr(0, dot).size()) major = -1;
    if (dot != std::string::npos) {
      minor = std::stoi(ver.substr(dot + 1), &used);
      if (used != ver.size() - dot - 1 || minor < 0) major = -1;
    }
  } catch (const std::exception&) {
    major = -1;
  }
  if (major < 1) bad(source, "format", "cannot read the version of " + shown(*it));
  if (major > kModelFormatMajor)
    bad(source, "format",
        f + " was written by a newer rotacal; this one reads " + kModelFormat +
            ": upgrade rotacal");
  if (major < kModelFormatMajor) bad(source, "format", f + " is older than any rotacal wrote");
  return minor;
}

// The R-test joint model's own members. Coefficient names are checked for their unit (d* are
// translations) and for agreeing with the covariance; that they are the basis' names is
// checked where the maps are evaluated (RtestJointModel), which owns the basis.
void check_rtest_joint(const json& doc, MachineType machine, const std::string& source) {
  const json& b = object_member(doc, "basis", source);
  for (const char* key : {"b_degree", "c_harmonics", "c_b_degree"}) {
    const json& v = member(b, key, source, "basis");
    if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > 32)
      bad(source, std::string("basis.") + key, "must be an integer 0..32, got " + shown(v));
  }
  const json& g = member(b, "gamma_cb", source, "basis");
  if (!g.is_boolean()) bad(source, "basis.gamma_cb", "must be true or false, got " + shown(g));
  if (b.contains("maps")) {
    const auto maps = rtest_map_names(machine);
    if (b["maps"] != json(std::vector<std::string>(maps.begin(), maps.end())))
      bad(source, "basis.maps",
          shown(b["maps"]) + " are not the " + to_string(machine) + " machine's maps [\"" +
              maps[0] + "\", \"" + maps[1] + "\"]");
  }
  std::vector<std::string> names(location_error_names(machine).begin(),
                                 location_error_names(machine).end());
  // A machine with head axes also fits tool_offset_Z (minus the error of pivot + tool length).
  if (machine.has_head()) {
    estimate(member(doc, "tool_offset_Z", source, ""), "tool_offset_Z", "mm",
             kMaxModelPositionError, source);
    names.push_back("tool_offset_Z");
  } else if (doc.contains("tool_offset_Z")) {
    bad(source, "tool_offset_Z",
        "only a machine with head axes has it; " + to_string(machine) + " has none");
  }
  const json& mc = object_member(doc, "map_coefficients", source);
  for (auto it = mc.begin(); it != mc.end(); ++it) {
    const std::string& n = it.key();
    const bool angle = n.rfind("d", 0) != 0;
    const json& e = it.value();
    estimate(e.is_object() ? e : json{{"value", e}}, "map_coefficients." + n, angle ? "rad" : "mm",
             angle ? kMaxModelAngleError : kMaxModelPositionError, source);
    names.push_back(n);
  }
  const json& cov = object_member(doc, "covariance", source);
  const json& params = member(cov, "parameters", source, "covariance");
  if (params != json(names))
    bad(source, "covariance.parameters",
        "must list the " + std::to_string(names.size()) +
            " parameters (location errors, tool_offset_Z on a machine with head "
            "axes, then map_coefficients in order)");
  const json& m = member(cov, "matrix", source, "covariance");
  if (!m.is_array() || m.size() != names.size())
    bad(source, "covariance.matrix", "must be " + std::to_string(names.size()) + " rows");
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (!m[i].is_array() || m[i].size() != names.size())
      bad(source, "covariance.matrix[" + std::to_string(i) + "]",
          "must be " + std::to_string(names.size()) + " numbers");
    for (const json& x : m[i])
      if (!x.is_number() && !x.is_null())
        bad(source, "covariance.matrix[" + std::to_string(i) + "]",
            "must hold numbers (or null), got " + shown(x));
  }
  if (doc.contains("nests")) {
    const json& nests = object_member(doc, "nests", source);
    for (auto it = nests.begin(); it != nests.end(); ++it) {
      const json& v = it.value();
      if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() ||
          !v[2].is_number())
        bad(source, "nests." + it.key(), "must be 3 numbers (mm), got " + shown(v));
      for (const json& x : v)
        if (std::fabs(x.get<double>()) > kMaxModelPivot)
          bad(source, "nests." + it.key(),
              shown(v) + " is beyond " + json(kMaxModelPivot).dump() + " mm");
    }
  }
}

void probe_zeros(const json& doc, const std::string& source) {
  if (!doc.contains("probe_zeros")) return;
  const json& z = object_member(doc, "probe_zeros", source);
  for (auto it = z.begin(); it != z.end(); ++it) {
    if (!it.value().is_object())
      bad(source, "probe_zeros." + it.key(), "must be an object {x, y, z}");
    for (const char* a : {"x", "y", "z"})
      estimate(member(it.value(), a, source, "probe_zeros." + it.key()),
               "probe_zeros." + it.key() + "." + a, "mm", kMaxModelPositionError, source);
  }
}

void nullify(json& v, const std::string& pointer, json& reasons) {
  if (v.is_number_float()) {
    const double x = v.get<double>();
    if (!std::isfinite(x)) {
      reasons[pointer] = std::isnan(x) ? "NaN: not determined by the data"
                                       : (x > 0 ? "+Infinity: not determined by the data"
                                                : "-Infinity: not determined by the data");
      v = nullptr;
    }
  } else if (v.is_object()) {
    for (auto it = v.begin(); it != v.end(); ++it) {
      std::string key = it.key();
      // RFC 6901 escapes: ~ -> ~0, / -> ~1.
      std::string esc;
      for (char c : key)
        esc += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
      nullify(it.value(), pointer + "/" + esc, reasons);
    }
  } else if (v.is_array()) {
    for (std::size_t i = 0; i < v.size(); ++i)
      nullify(v[i], pointer + "/" + std::to_string(i), reasons);
  }
}

// Format and version, kind, machine: what every use of a model file needs.
void check_envelope(const json& doc, const std::string& source, ModelFile& m) {
  if (!doc.is_object()) bad(source, "", "a model file is a JSON object, got " + shown(doc));
  m.format_minor = format_minor(doc, source);
  const json& kind = member(doc, "kind", source, "");
  if (!kind.is_string() || !kKinds.count(kind.get<std::string>()))
    bad(source, "kind",
        shown(kind) +
            " is not one of ballbar, rtest-joint, rtest-diagnosis, probe, multi, thermal");
  m.kind = kind.get<std::string>();
  const json& machine = member(doc, "machine", source, "");
  if (!machine.is_string())
    bad(source, "machine", "must be a string such as \"AC-trt\", got " + shown(machine));
  // As in sessions: a machine_description defines the machine, `machine` is then its name.
  if (doc.contains("machine_description")) {
    const json& d = doc["machine_description"];
    if (!d.is_object())
      bad(source, "machine_description", "must be a rotacal-machine/1 object, got " + shown(d));
    try {
      m.machine = MachineType::from_description(
          parse_machine_description(d.dump(), source + ": machine_description"));
    } catch (const InvalidArgument& e) {
      bad(source, "machine_description", e.what());
    }
    return;
  }
  try {
    m.machine = parse_machine_type(machine.get<std::string>());
  } catch (const InvalidArgument& e) {
    bad(source, "machine", e.what());
  }
}

// The machine members of a document: the name, and for every machine but the two tables of
// formats.md its description (as in sessions).
void put_machine(json& doc, MachineType m) {
  doc["machine"] = to_string(m);
  if (m != MachineType::AC_trt && m != MachineType::BC_trt)
    doc["machine_description"] = json::parse(machine_description_json(m.description()));
}

std::string read_text(const std::string& path) {
  if (path.find('\0') != std::string::npos)
    throw IoError(std::string(path.c_str()) + "...: path contains a NUL byte");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(path + ": cannot open for reading: " + std::strerror(errno));
  struct stat st{};
  if (::fstat(fd, &st) != 0 || S_ISDIR(st.st_mode)) {
    ::close(fd);
    throw IoError(path + ": is a directory, not a model file");
  }
  std::string text;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      throw IoError(path + ": read failed: " + std::strerror(err));
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > kMaxModelFileBytes) {
      ::close(fd);
      throw IoError(path + ": larger than " + std::to_string(kMaxModelFileBytes >> 20) +
                    " MB: not a model file");
    }
  }
  ::close(fd);
  return text;
}

}  // namespace

json read_model_document(const std::string& path) {
  json doc = parse_json(read_text(path), path);
  ModelFile envelope;
  check_envelope(doc, path, envelope);
  // Nothing later reads a probe or multi model's own members member by member: all checked now.
  if (envelope.kind == "probe" || envelope.kind == "multi" || envelope.kind == "thermal")
    model_from_json(doc, path);
  return doc;
}

ModelFile model_from_json(const json& doc, const std::string& source) {
  ModelFile m;
  check_envelope(doc, source, m);
  static const json kEmpty = json::object();
  const json& le = doc.contains("location_errors") ? doc["location_errors"] : kEmpty;
  if (!le.is_object()) bad(source, "location_errors", "must be an object, got " + shown(le));
  const auto& names = location_error_names(m.machine);
  std::string lacking;
  for (const std::string& n : names)
    if (!le.contains(n)) lacking += (lacking.empty() ? "" : ", ") + n;
  if (!lacking.empty()) bad(source, "", "location_errors lacks " + lacking);
  for (int k = 0; k < 8; ++k) {
    const bool angle = location_error_is_angle(k);
    const std::optional<double> v = estimate(
        member(le, names[k], source, "location_errors"), "location_errors." + names[k],
        angle ? "rad" : "mm", angle ? kMaxModelAngleError : kMaxModelPositionError, source);
    m.location_errors.v[k] = v.value_or(0.0);
    m.observable[static_cast<std::size_t>(k)] = v.has_value();
  }
  for (auto it = le.begin(); it != le.end(); ++it)
    if (std::find(names.begin(), names.end(), it.key()) == names.end())
      bad(source, "location_errors." + it.key(),
          "is not a location error of a " + to_string(m.machine) + " machine");
  if (m.kind == "ballbar") {
    const json& pv = object_member(doc, "pivot", source);
    Eigen::Vector3d p;
    for (int a = 0; a < 3; ++a) {
      const std::string axis(1, "xyz"[a]);
      p[a] =
          estimate(member(pv, axis, source, "pivot"), "pivot." + axis, "mm", kMaxModelPivot, source)
              .value_or(0.0);
    }
    m.pivot = p;
  }
  if (doc.contains("effects")) {
    const json& fx = doc["effects"];
    if (!fx.is_array()) bad(source, "effects", "must be a list, got " + shown(fx));
    for (std::size_t i = 0; i < fx.size(); ++i) {
      const std::string where = "effects[" + std::to_string(i) + "]";
      if (!fx[i].is_object()) bad(source, where, "must be an object {\"id\", \"params\"}");
      const json& id = member(fx[i], "id", source, where);
      if (!id.is_string()) bad(source, where + ".id", "must be a string, got " + shown(id));
      Effect e;
      try {
        e = Effect::parse(id.get<std::string>());
      } catch (const InvalidArgument& ex) {
        bad(source, where + ".id", ex.what());
      }
      if (!e.applies_to(m.machine))
        bad(source, where + ".id",
            id.get<std::string>() + " does not exist on a " + to_string(m.machine) + " machine");
      const json& params = object_member(fx[i], "params", source, where);
      const auto pn = e.param_names();
      const auto pu = e.param_units();
      for (std::size_t k = 0; k < pn.size(); ++k) {
        // Effect parameters have no single physical bound; finite and unit-checked.
        const std::optional<double> v = estimate(member(params, pn[k], source, where + ".params"),
                                                 where + ".params." + pn[k], pu[k], 1.0e6, source);
        m.effect_params.push_back(v.value_or(0.0));
      }
      m.effects.effects.push_back(e);
    }
  }
  if (m.kind == "rtest-joint") check_rtest_joint(doc, m.machine, source);
  if (m.kind == "probe" || m.kind == "multi") fitted_model_from_json(doc, m.machine, source);
  if (m.kind == "thermal") check_thermal_model(doc, m.machine, source);
  probe_zeros(doc, source);
  if (doc.contains("null_reasons") && !doc["null_reasons"].is_object())
    bad(source, "null_reasons", "must be an object (JSON pointer -> reason)");
  m.document = doc;
  return m;
}

ModelFile parse_model(const std::string& text, const std::string& source) {
  return model_from_json(parse_json(text, source), source);
}

ModelFile read_model(const std::string& path) {
  ModelFile m = model_from_json(parse_json(read_text(path), path), path);
  // Its location_errors are the cold ones: a use that knows no lag state would take them.
  if (m.kind == "thermal")
    bad(path, "kind",
        "a thermal model: its location errors drift as the axis runs; predict them with "
        "`rotacal predict --duty` or export them at a state with `rotacal export --at/--state` "
        "(docs/thermal.md)");
  return m;
}

json strict_json(json document) {
  json reasons = json::object();
  nullify(document, "", reasons);
  if (!reasons.empty()) {
    json& all = document["null_reasons"];
    if (!all.is_object()) all = json::object();
    for (auto it = reasons.begin(); it != reasons.end(); ++it) all[it.key()] = it.value();
  }
  return document;
}

std::string format_model(const json& document, const std::string& source) {
  const json doc = strict_json(document);
  model_from_json(doc, source);  // never write what the reader would refuse
  return doc.dump(2) + "\n";
}

void write_model(const json& document, const std::string& path, const OutputOptions& options) {
  write_output(path, [&] { return format_model(document, path); }, options);
}

json model_document_header(const std::string& kind, MachineType machine) {
  json doc = {{"format", kModelFormat}, {"kind", kind}};
  put_machine(doc, machine);
  return doc;
}

namespace {

// What the basis' coefficients mean (rotacal/rtest/identify_joint.hpp), written into the file
// so that a reader without the library can evaluate the maps.
const char* const kRtestBasisDefinition =
    "b = B / 90 deg. Table pose T(B, C) = E(w_BY(B)) Rot(B line, B) E(w_CB(B, C)) Rot(C line, C), "
    "E(w) = Dx(dx) Dy(dy) Dz(dz) Da(alpha) Db(beta) Dc(gamma) (Oyama & Ibaraki Eq. 1), axis lines "
    "from the location errors (ISO 230-7). w_BY translations: coefficient 'k_BY.bP' multiplies "
    "b^P (even P >= 2); rotations: odd P >= 1. w_CB component k: 'k_CB.cosN.bM' multiplies "
    "b^M cos(N C), 'k_CB.sinN.bM' b^M sin(N C); 'dxy_CB.back1.u.b0' adds (cos C, -sin C) to "
    "(dx, dy)_CB and '.v.b0' (sin C, cos C), likewise 'alphabeta_CB.back1' for (alpha, beta)_CB. "
    "R-test reading of the nest at q: d = T^-1 (Ry(B) Rz(C) q) - q + probe zero. Units mm, rad. "
    "On another machine B is its tilt axis and C its rotary axis; basis.maps names their maps "
    "(coefficients 'dz_<tilt map>.b2', 'dx_<rotary map>.cos1.b0', ...), each E(w) stands in front "
    "of its own axis' rotation in the machine's chain (docs/machines.md), an axis on the head has "
    "translations only, and the tool ball is at (0, 0, -(pivot + tool length) + tool_offset_Z) in "
    "the spindle frame.";

// {"value", "std", "unit"}; an unobservable parameter keeps its convention value, no std.
json convention_estimate(const ParameterEstimate& p) {
  if (!p.observable)
    return {{"value", p.value}, {"std", nullptr}, {"unit", p.unit}, {"observable", false}};
  return {{"value", p.value}, {"std", p.std}, {"unit", p.unit}};
}

}  // namespace

json rtest_joint_model_document(const RtestJointModelContent& c) {
  const std::size_t n_le = 8, n_head = c.machine.has_head() ? 1 : 0, n = c.parameters.size();
  if (n < n_le + n_head)
    throw InvalidArgument("rtest_joint_model_document: " + std::to_string(n) +
                          " parameters, fewer than the " + std::to_string(n_le + n_head) +
                          " of the machine");
  if (c.covariance.rows() != static_cast<Eigen::Index>(n) ||
      c.covariance.cols() != static_cast<Eigen::Index>(n))
    throw InvalidArgument("rtest_joint_model_document: the covariance is not " + std::to_string(n) +
                          " x " + std::to_string(n));
  json doc = model_document_header("rtest-joint", c.machine);
  json maps = json::array();
  for (const std::string& m : rtest_map_names(c.machine)) maps.push_back(m);
  doc["basis"] = {{"b_degree", c.b_degree},
                  {"c_harmonics", c.c_harmonics},
                  {"c_b_degree", c.c_b_degree},
                  {"gamma_cb", c.gamma_cb},
                  {"maps", maps},
                  {"definition", kRtestBasisDefinition}};
  json le = json::object(), coefficients = json::object(), names = json::array(),
       matrix = json::array();
  for (std::size_t i = 0; i < n_le; ++i)
    le[c.parameters[i].name] = convention_estimate(c.parameters[i]);
  doc["location_errors"] = le;
  if (n_head) doc[c.parameters[n_le].name] = convention_estimate(c.parameters[n_le]);
  for (std::size_t i = n_le + n_head; i < n; ++i)
    coefficients[c.parameters[i].name] = convention_estimate(c.parameters[i]);
  doc["map_coefficients"] = coefficients;
  for (std::size_t i = 0; i < n; ++i) {
    names.push_back(c.parameters[i].name);
    json row = json::array();
    for (std::size_t j = 0; j < n; ++j)
      row.push_back(c.covariance(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)));
    matrix.push_back(row);
  }
  doc["covariance"] = {{"parameters", names}, {"matrix", matrix}};
  json nests = json::object(), zeros = json::object();
  for (const auto& [label, q] : c.nests) nests[label] = {q.x(), q.y(), q.z()};
  doc["nests"] = nests;
  for (const auto& [setup, z] : c.probe_zeros)
    zeros[setup] = {{"x", convention_estimate(z[0])},
                    {"y", convention_estimate(z[1])},
                    {"z", convention_estimate(z[2])}};
  doc["probe_zeros"] = zeros;
  doc["fit"] = {{"residual_rms_um", c.residual_rms_um},
                {"sigma_um", c.sigma_um},
                {"n_samples", c.n_samples},
                {"converged", c.converged},
                {"unobservable", c.unobservable},
                {"notes", c.notes}};
  return doc;
}

}  // namespace rotacal
