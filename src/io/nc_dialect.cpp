// SPDX-License-Identifier: BSD-3-Clause
// The NC dialects by name (io/nc_dialect.hpp).
#include "rotacal/io/nc_dialect.hpp"

#include "rotacal/core/error.hpp"

namespace rotacal {

std::string to_string(NcDialect dialect) {
  switch (dialect) {
    case NcDialect::linuxcnc:
      return "linuxcnc";
    case NcDialect::heidenhain:
      return "heidenhain";
    case NcDialect::siemens:
      return "siemens";
    case NcDialect::fanuc:
      return "fanuc";
  }
  ROTACAL_ASSERT(false);
  return {};
}

NcDialect parse_nc_dialect(const std::string& text) {
  for (NcDialect d :
       {NcDialect::linuxcnc, NcDialect::heidenhain, NcDialect::siemens, NcDialect::fanuc})
    if (to_string(d) == text) return d;
  throw InvalidArgument("unknown NC dialect '" + text +
                        "' (known: linuxcnc, heidenhain, siemens, fanuc)");
}

}  // namespace rotacal
