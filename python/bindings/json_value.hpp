// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// JSON values (nlohmann) as Python objects (dicts of str keys, lists, numbers, None), for the
/// bindings that return a model document (defined in io.cpp).

#include <nlohmann/json.hpp>

#include "numpy.hpp"

namespace rotacal::py {

pyb::object from_json(const nlohmann::ordered_json& j);

}  // namespace rotacal::py
