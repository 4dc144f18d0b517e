// SPDX-License-Identifier: BSD-3-Clause
// R-test error maps (Oyama & Ibaraki): tabulated from the paper method, written as CSV and JSON.
#include "rotacal/rtest/error_map.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "rotacal/core/angles.hpp"
#include "rotacal/core/error.hpp"
#include "rotacal/io/output_file.hpp"

namespace rotacal {

namespace {
std::string num(double v) {
  if (!std::isfinite(v)) return "";
  char b[40];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}
}  // namespace

RtestErrorMap error_map(const RtestJointIdentification& id, const std::vector<double>& b_deg,
                        const std::vector<double>& c_deg) {
  RtestErrorMap m;
  m.method = id.method;
  m.notes = id.notes;
  m.machine = id.model.machine;
  m.maps = rtest_map_names(m.machine);
  m.letters = {tilt_axis_letter(m.machine), rot_axis_letter(m.machine)};
  for (double b : b_deg)
    for (double c : c_deg) {
      RtestErrorMapEntry e;
      e.b_deg = b;
      e.c_deg = c;
      e.w_BY = id.model.w_BY(b * kDeg, &e.w_BY_std);
      e.w_CB = id.model.w_CB(b * kDeg, c * kDeg, &e.w_CB_std);
      m.entries.push_back(e);
    }
  return m;
}

RtestErrorMap error_map(const RtestPaperIdentification& id) {
  RtestErrorMap m;
  m.method = id.method;
  m.notes = id.notes;
  for (std::size_t i = 0; i < id.b_deg.size(); ++i)
    for (std::size_t j = 0; j < id.c_deg.size(); ++j) {
      RtestErrorMapEntry e;
      e.b_deg = id.b_deg[i];
      e.c_deg = id.c_deg[j];
      e.w_BY = id.w_BY[i];
      e.w_BY_std = id.w_BY_std[i];
      e.w_CB = id.w_CB[i][j];
      e.w_CB_std = id.w_CB_std[i][j];
      e.w_CB_std[5] = std::numeric_limits<double>::quiet_NaN();  // assumed, not identified
      m.entries.push_back(e);
    }
  return m;
}

std::string error_map_csv(const RtestErrorMap& map) {
  std::ostringstream o;
  o << map.letters[0] << "," << map.letters[1];
  for (const char* suffix : {"", "_std"})
    for (const std::string& ax : map.maps)
      for (int k = 0; k < 6; ++k) o << "," << oyama_error_name(k, ax) << suffix;
  o << "\n";
  for (const RtestErrorMapEntry& e : map.entries) {
    o << num(e.b_deg) << "," << num(e.c_deg);
    for (const AxisErrors<double>* w : {&e.w_BY, &e.w_CB, &e.w_BY_std, &e.w_CB_std})
      for (int k = 0; k < 6; ++k) o << "," << num((*w)[k]);
    o << "\n";
  }
  return o.str();
}

std::string error_map_json(const RtestErrorMap& map) {
  using ojson = nlohmann::ordered_json;
  // Strict JSON through nlohmann (escaping of every string, shortest round-trip numbers); a
  // non-finite value is written null, and "null_means" says why rather than a silent null.
  bool any_null = false;
  auto vec = [&](const AxisErrors<double>& w) {
    ojson a = ojson::array();
    for (int k = 0; k < 6; ++k) {
      if (std::isfinite(w[k])) {
        a.push_back(w[k]);
      } else {
        a.push_back(nullptr);
        any_null = true;
      }
    }
    return a;
  };
  ojson head;
  head["method"] = map.method;
  head["machine"] = to_string(map.machine);
  head["angles"] = {std::string(1, map.letters[0]), std::string(1, map.letters[1])};
  head["maps"] = {map.maps[0], map.maps[1]};
  head["order"] = {"dx", "dy", "dz", "alpha", "beta", "gamma"};
  head["units"] = {"mm", "mm", "mm", "rad", "rad", "rad"};
  head["notes"] = map.notes;
  std::vector<std::string> rows;
  for (const RtestErrorMapEntry& e : map.entries) {
    if (!std::isfinite(e.b_deg) || !std::isfinite(e.c_deg))
      throw InvalidArgument("error_map_json: an entry's B or C is not finite");
    ojson row;
    row[std::string(1, map.letters[0])] = e.b_deg;
    row[std::string(1, map.letters[1])] = e.c_deg;
    row[map.maps[0]] = vec(e.w_BY);
    row[map.maps[0] + "_std"] = vec(e.w_BY_std);
    row[map.maps[1]] = vec(e.w_CB);
    row[map.maps[1] + "_std"] = vec(e.w_CB_std);
    rows.push_back(row.dump());
  }
  if (any_null)
    head["null_means"] =
        "a null std: the component is assumed, not identified, by this method (e.g. gamma_CB of "
        "the "
        "paper method, Oyama & Ibaraki Sec. 4.2); a null value: not determined by the data";
  // One entry per line keeps an 84-pose map readable; the rest is nlohmann's indented dump.
  std::string text = head.dump(2);
  text.pop_back();  // the closing brace
  text += ",\n  \"entries\": [\n";
  for (std::size_t i = 0; i < rows.size(); ++i)
    text += "    " + rows[i] + (i + 1 < rows.size() ? ",\n" : "\n");
  return text + "  ]\n}\n";
}

void write_text_file(const std::string& path, const std::string& text) { write_output(path, text); }

double prediction_rms_um(const RtestSession& session, const RtestPredictor& predict) {
  if (session.samples.empty()) throw InvalidArgument("prediction_rms_um: session has no samples");
  double ss = 0.0;
  std::size_t n = 0;
  for (const std::string& setup : session.setups()) {
    const auto it = session.nests.find(setup);
    if (it == session.nests.end())
      throw InvalidArgument("prediction_rms_um: session.nests: no nest." + setup);
    std::vector<Eigen::Vector3d> r;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t i : session.indices_of(setup)) {
      const RtestSample& s = session.samples[i];
      if (!s.d) throw InvalidArgument("prediction_rms_um: a sample has no dx,dy,dz");
      r.push_back(*s.d - predict(it->second, s.angles_rad().tilt, s.angles_rad().rot));
      mean += r.back();
    }
    mean /= static_cast<double>(r.size());
    for (const auto& v : r) ss += (v - mean).squaredNorm(), n += 3;
  }
  return std::sqrt(ss / static_cast<double>(n)) * 1e3;
}

}  // namespace rotacal
