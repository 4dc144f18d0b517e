// SPDX-License-Identifier: BSD-3-Clause
// The member checks shared by the kinds of rotacal-model/1 files (model_checks.hpp).
#include "model_checks.hpp"

#include <cmath>

#include "rotacal/core/error.hpp"

namespace rotacal::model_checks {

[[noreturn]] void bad(const std::string& source, const std::string& where,
                      const std::string& what) {
  throw InvalidArgument(source + ": " + (where.empty() ? "" : where + ": ") + what);
}

std::string shown(const json& v) {
  std::string s = v.dump();
  if (s.size() > 80) s = s.substr(0, 77) + "...";
  return s;
}

const json& member(const json& obj, const std::string& key, const std::string& source,
                   const std::string& where) {
  const auto it = obj.find(key);
  if (it == obj.end()) bad(source, where.empty() ? key : where + "." + key, "missing");
  return *it;
}

const json& object_member(const json& obj, const std::string& key, const std::string& source,
                          const std::string& where) {
  const json& v = member(obj, key, source, where);
  if (!v.is_object())
    bad(source, where.empty() ? key : where + "." + key, "must be an object, got " + shown(v));
  return v;
}

std::optional<double> estimate(const json& e, const std::string& where, const std::string& unit,
                               double limit, const std::string& source) {
  if (!e.is_object())
    bad(source, where, "must be an object {\"value\", \"std\", \"unit\"}, got " + shown(e));
  const json& v = member(e, "value", source, where);
  if (e.contains("unit")) {
    const json& u = e["unit"];
    if (!u.is_string() || u.get<std::string>() != unit)
      bad(source, where + ".unit", shown(u) + ": this parameter is in " + unit);
  }
  if (e.contains("std")) {
    const json& s = e["std"];
    if (!s.is_null() && (!s.is_number() || !(s.get<double>() >= 0.0)))
      bad(source, where + ".std", "must be a number >= 0 or null, got " + shown(s));
  }
  if (v.is_null()) return std::nullopt;
  if (!v.is_number()) bad(source, where + ".value", "must be a number or null, got " + shown(v));
  const double x = v.get<double>();
  if (!std::isfinite(x) || std::fabs(x) > limit)
    bad(source, where + ".value",
        shown(v) + " " + unit + " is beyond " + json(limit).dump() + " " + unit +
            ", which no machine tool has");
  return x;
}

}  // namespace rotacal::model_checks
