// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The member checks every kind of rotacal-model/1 file shares (model_file.cpp,
// fitted_model.cpp): messages "source: member: what is wrong", an estimate's value, unit and
// std, an object member.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace rotacal::model_checks {

using json = nlohmann::ordered_json;

/// Throws InvalidArgument "source: where: what" (no "where: " when it is empty).
[[noreturn]] void bad(const std::string& source, const std::string& where, const std::string& what);
/// At most ~80 characters of a value, for a message.
std::string shown(const json& v);
/// obj[key], or InvalidArgument "source: where.key: missing".
const json& member(const json& obj, const std::string& key, const std::string& source,
                   const std::string& where);
/// member() that must be an object.
const json& object_member(const json& obj, const std::string& key, const std::string& source,
                          const std::string& where = "");
/// One {"value", "std", "unit"} entry checked (unit as given, |value| <= limit, std >= 0 or
/// null); its value, nullopt when null (unobservable).
std::optional<double> estimate(const json& e, const std::string& where, const std::string& unit,
                               double limit, const std::string& source);

}  // namespace rotacal::model_checks
