// SPDX-License-Identifier: BSD-3-Clause
// Location errors into controllers' kinematic parameters: the controllers by name, the export
// input of a model file, and the export of each controller (one file each in this folder).
#include "rotacal/io/controller_export.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "rotacal/core/error.hpp"
#include "rotacal/io/fitted_model.hpp"
#include "shared.hpp"

namespace rotacal {

using namespace export_detail;

namespace {

const std::map<std::string, Controller>& controller_names() {
  static const std::map<std::string, Controller> names = {{"linuxcnc", Controller::linuxcnc},
                                                          {"siemens", Controller::siemens},
                                                          {"isg", Controller::isg},
                                                          {"heidenhain", Controller::heidenhain},
                                                          {"fanuc", Controller::fanuc}};
  return names;
}

// The exports map the two table machines' errors onto their controllers' table kinematics, and
// LinuxCNC's the two head machines it ships a module for (docs/controller_exports.md). Any other
// machine is refused with the kinematics the controller's export lacks for it.
void require_exportable(Controller c, MachineType m) {
  if (m == MachineType::AC_trt || m == MachineType::BC_trt) return;
  if (c == Controller::linuxcnc && !linuxcnc_head_kinematics(m).empty()) return;
  const std::string kind = m.description().configuration();
  std::string lacks;
  switch (c) {
    case Controller::linuxcnc:
      lacks =
          "LinuxCNC 2.9 ships no kinematics module for it (xyzac-trt-kins and xyzbc-trt-kins: "
          "the AC/BC tables; maxkins: B-head-C-table; 5axiskins: BC-head)";
      break;
    case Controller::siemens:
      lacks =
          "the SINUMERIK export writes $TC_CARR type P (table-table) only, not the types T "
          "(head-table) or M (head-head) nor a nutating axis";
      break;
    case Controller::isg:
      lacks =
          "the ISG export writes the universal kinematic (ID 91) of an AC/BC table only, not "
          "the kinematic IDs of head or nutating machines";
      break;
    case Controller::heidenhain:
      lacks =
          "the HEIDENHAIN mapping covers the kinematics table of an AC/BC table only, not the "
          "head or nutating axes' rows";
      break;
    case Controller::fanuc:
      lacks =
          "the FANUC mapping covers tool centre point control with two table axes (No. 19680 "
          "= 12) only, not the head or nutating machine types";
      break;
  }
  throw InvalidArgument("export --controller " + to_string(c) + ": a " + to_string(m) + " (" +
                        kind + ") machine: " + lacks +
                        "; its identified errors are in its model file (--save-model), for "
                        "rotacal compensate --model");
}

}  // namespace

Controller parse_controller(const std::string& name, const std::string& option) {
  const auto it = controller_names().find(name);
  if (it != controller_names().end()) return it->second;
  std::string known;
  for (const auto& [n, c] : controller_names()) known += (known.empty() ? "" : ", ") + n;
  throw InvalidArgument(option + " '" + name + "': unknown controller (one of " + known + ")");
}

std::string to_string(Controller c) {
  for (const auto& [n, k] : controller_names())
    if (k == c) return n;
  return "?";
}

ExportInput export_input(const ModelFile& model, const std::string& model_path) {
  if (model.kind == "multi") {  // sessions that disagree make no model to load on a machine
    const FittedModelContent c = fitted_model_content(model, model_path);
    if (!c.disagreements.empty() && !c.sigma_inflated) {
      std::string what;
      for (const FittedDisagreement& d : c.disagreements)
        what += (what.empty() ? "" : "; ") + d.parameter + " (" + d.session_a + " vs " +
                d.session_b + ")";
      throw InvalidArgument(model_path +
                            ": the sessions of this joint model disagree: " + what.substr(0, 600) +
                            "; it is not exported (identify again without the session in "
                            "error, or with --inflate-sigma)");
    }
  }
  ExportInput in;
  in.machine = model.machine;
  in.errors = model.location_errors;
  in.observable = model.observable;
  in.model_path = model_path;
  const auto& names = location_error_names(model.machine);
  const nlohmann::ordered_json& doc = model.document;
  for (int i = 0; i < 8; ++i) {
    const auto& e = doc.at("location_errors").at(names[static_cast<std::size_t>(i)]);
    const double s = e.contains("std") && e["std"].is_number() ? e["std"].get<double>() : 0.0;
    in.covariance(i, i) = s * s;
  }
  if (doc.contains("covariance") && doc["covariance"].is_object()) {
    const auto& cov = doc["covariance"];
    const auto& params = cov.at("parameters");
    std::array<int, 8> at{};
    bool all = true;
    for (int i = 0; i < 8; ++i) {
      at[static_cast<std::size_t>(i)] = -1;
      for (std::size_t j = 0; j < params.size(); ++j)
        if (params[j] == names[static_cast<std::size_t>(i)])
          at[static_cast<std::size_t>(i)] = static_cast<int>(j);
      all = all && at[static_cast<std::size_t>(i)] >= 0;
    }
    if (all) {
      bool finite = true;
      Eigen::Matrix<double, 8, 8> c;
      for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j) {
          const auto& x = cov.at("matrix")
                              .at(static_cast<std::size_t>(at[static_cast<std::size_t>(i)]))
                              .at(static_cast<std::size_t>(at[static_cast<std::size_t>(j)]));
          finite = finite && x.is_number();
          c(i, j) = x.is_number() ? x.get<double>() : 0.0;
        }
      if (finite) {
        in.covariance = c;
        in.full_covariance = true;
      }
    }
  }
  if (doc.contains("source") && doc["source"].is_object()) {
    const auto& s = doc["source"];
    auto str = [&](const char* k) {
      return s.contains(k) && s[k].is_string() ? s[k].get<std::string>() : std::string();
    };
    in.source = str("session");
    if (!str("identified_at").empty()) in.source += " on " + str("identified_at");
    if (!str("session_sha256").empty())
      in.source += " (sha256 " + str("session_sha256").substr(0, 16) + "...)";
  }
  return in;
}

ControllerExport export_kinematics(Controller c, const ExportInput& in, const ExportOptions& o) {
  require_exportable(c, in.machine);
  if (o.toolholder < 1 || o.toolholder > 99)
    throw InvalidArgument("--toolholder " + std::to_string(o.toolholder) + ": must be 1..99");
  const std::vector<std::string> known = current_parameter_names(c, in.machine, o.toolholder);
  for (const auto& [name, value] : o.current) {
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw InvalidArgument("current value '" + name + "' is not a parameter of the " +
                            to_string(c) + " export");
    if (!std::isfinite(value)) throw InvalidArgument("current value '" + name + "' is not finite");
  }
  switch (c) {
    case Controller::linuxcnc:
      return export_linuxcnc(in, o);
    case Controller::siemens:
      return export_siemens(in, o);
    case Controller::isg:
      return export_isg(in, o);
    case Controller::heidenhain:
      return export_heidenhain(in, o);
    case Controller::fanuc:
      return export_fanuc(in, o);
  }
  throw InvalidArgument("export: unknown controller");
}

std::vector<std::string> current_parameter_names(Controller c, MachineType machine,
                                                 int toolholder) {
  require_exportable(c, machine);
  ExportInput in;
  in.machine = machine;
  in.observable.fill(true);
  ExportOptions o;
  o.toolholder = toolholder;
  o.generated_at = "-";
  ControllerExport ex;
  switch (c) {
    case Controller::linuxcnc:
      ex = export_linuxcnc(in, o);
      break;
    case Controller::siemens:
      ex = export_siemens(in, o);
      break;
    case Controller::isg:
      ex = export_isg(in, o);
      break;
    case Controller::heidenhain:
      ex = export_heidenhain(in, o);
      break;
    case Controller::fanuc:
      ex = export_fanuc(in, o);
      break;
  }
  std::vector<std::string> names;
  for (const ControllerValue& v : ex.values) {
    const std::size_t cut = c == Controller::fanuc     ? 9
                            : c == Controller::siemens ? v.name.find(' ')
                                                       : std::string::npos;
    names.push_back(v.name.substr(0, cut));
  }
  return names;
}

}  // namespace rotacal
