#pragma once
// Internal to src/ballbar: number formatting of NC words and comments, shared by the NC writer
// of the rotary-axis test (nc_program.cpp) and of the circular tests (circular_test.cpp).

#include <cstdio>
#include <string>

namespace rotacal::nc_detail {

/// Fixed-point text with `decimals` digits; "-0.0000" is written as "0.0000".
inline std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  bool all_zero = true;
  for (char c : s)
    if (c != '-' && c != '0' && c != '.') all_zero = false;
  if (all_zero && !s.empty() && s[0] == '-') s.erase(0, 1);
  return s;
}

/// Up to 9 significant digits, for comments.
inline std::string general(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace rotacal::nc_detail
