// SPDX-License-Identifier: BSD-3-Clause
// The controller's current values, from its own text (a LinuxCNC HAL file, a SINUMERIK MPF) or
// from the small JSON form (docs/controller_exports.md).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/core/json_text.hpp"
#include "rotacal/io/controller_export.hpp"
#include "shared.hpp"

namespace rotacal {

namespace {
// A controller's offsets and pivots are within a machine's size: a kilometre (or 1e6 deg) is
// no value a controller holds, and 1e308 would be written back as a 309-digit number.
constexpr double kMaxCurrent = 1e6;
const char* const kMaxCurrentText = "1e6";
bool plausible_current(double v) { return std::isfinite(v) && std::abs(v) <= kMaxCurrent; }
}  // namespace

std::map<std::string, double> parse_current_parameters(Controller c, MachineType machine,
                                                       const std::string& text,
                                                       const std::string& source, int toolholder) {
  const std::vector<std::string> known = current_parameter_names(c, machine, toolholder);
  auto is_known = [&](const std::string& n) {
    return std::find(known.begin(), known.end(), n) != known.end();
  };
  std::map<std::string, double> out;
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '{') {  // the documented JSON
    const nlohmann::ordered_json j =
        parse_json(text, source);  // bounded, strict; ParseError names the line
    if (!j.is_object() || !j.contains("parameters") || !j["parameters"].is_object())
      throw InvalidArgument(source +
                            ": expected {\"controller\": ..., \"parameters\": {name: value}}");
    if (j.contains("controller") && j["controller"] != to_string(c))
      throw InvalidArgument(source + ": values of controller " + j["controller"].dump() +
                            ", export for " + to_string(c));
    for (const auto& [name, value] : j["parameters"].items()) {
      if (!is_known(name))
        throw InvalidArgument(source + ": parameters." + name + ": not a parameter of this export");
      if (!value.is_number() || !plausible_current(value.get<double>()))
        throw InvalidArgument(source + ": parameters." + name +
                              ": must be a finite number of at most " + kMaxCurrentText +
                              " (mm or deg)");
      out[name] = value.get<double>();
    }
    return out;
  }
  if (c != Controller::linuxcnc && c != Controller::siemens)
    throw InvalidArgument(source + ": current values of " + to_string(c) +
                          " are read from the JSON form only");
  std::istringstream in(text);
  std::string line;
  int n = 0;
  const std::string head = export_detail::linuxcnc_head_kinematics(machine);
  const std::string kins = !head.empty()                    ? head + "."
                           : machine == MachineType::AC_trt ? "xyzac-trt-kins."
                                                            : "xyzbc-trt-kins.";
  while (std::getline(in, line)) {
    ++n;
    const std::string where = source + ":" + std::to_string(n);
    std::istringstream ls(line.substr(0, line.find(c == Controller::linuxcnc ? '#' : ';')));
    std::string name, value;
    if (c == Controller::linuxcnc) {
      std::string cmd;
      if (!(ls >> cmd) || cmd != "setp" || !(ls >> name) || name.rfind(kins, 0) != 0) continue;
      if (!(ls >> value)) throw InvalidArgument(where + ": setp " + name + " without a value");
      if (name == kins + "tool-offset" || name == kins + "conventional-directions" ||
          name == kins + "x-offset" || name == kins + "y-offset") {
        if (!is_known(name)) continue;  // read by the module but not changed by the export
      }
    } else {
      std::string stmt;
      std::getline(ls, stmt);
      const std::size_t eq = stmt.find('=');
      if (stmt.find("$TC_CARR") == std::string::npos || eq == std::string::npos) continue;
      auto trim = [](std::string s) {
        s.erase(0, s.find_first_not_of(" \t"));
        s.erase(s.find_last_not_of(" \t\r") + 1);
        return s;
      };
      name = trim(stmt.substr(0, eq));
      value = trim(stmt.substr(eq + 1));
      if (name.find("[" + std::to_string(toolholder) + "]") == std::string::npos)
        continue;                     // another data set
      if (!is_known(name)) continue;  // names, type, limits, fine offsets: kept as they are
    }
    if (!is_known(name))
      throw InvalidArgument(where + ": " + name + " is not a parameter of this export");
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (end == value.c_str() || *end != '\0' || !plausible_current(v))
      throw InvalidArgument(where + ": " + name + ": '" + value +
                            "' is not a finite number of at most " + kMaxCurrentText +
                            " (mm or deg)");
    out[name] = v;
  }
  if (out.empty())
    throw InvalidArgument(source + ": no current values of " + to_string(c) + " found");
  return out;
}

}  // namespace rotacal
