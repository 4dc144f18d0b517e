// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/session/session.hpp"

#include <algorithm>
#include <cmath>

namespace rotacal {

namespace {
constexpr double kDegToRad = M_PI / 180.0;

template <typename Sample, typename Key>
std::vector<std::string> distinct(const std::vector<Sample>& samples, Key key) {
  std::vector<std::string> out;
  for (const auto& s : samples)
    if (std::find(out.begin(), out.end(), key(s)) == out.end()) out.push_back(key(s));
  return out;
}

template <typename Sample, typename Key>
std::vector<std::size_t> where(const std::vector<Sample>& samples, const std::string& label,
                               Key key) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < samples.size(); ++i)
    if (key(samples[i]) == label) out.push_back(i);
  return out;
}
}  // namespace

RotaryAngles<double> BallbarSample::angles_rad() const {
  return {tilt_deg * kDegToRad, rot_deg * kDegToRad};
}
RotaryAngles<double> RtestSample::angles_rad() const {
  return {tilt_deg * kDegToRad, rot_deg * kDegToRad};
}

std::vector<std::string> BallbarSession::tests() const {
  return distinct(samples, [](const BallbarSample& s) -> const std::string& { return s.test; });
}
std::vector<std::size_t> BallbarSession::indices_of(const std::string& test) const {
  return where(samples, test, [](const BallbarSample& s) -> const std::string& { return s.test; });
}
std::vector<std::string> RtestSession::setups() const {
  return distinct(samples, [](const RtestSample& s) -> const std::string& { return s.setup; });
}
std::vector<std::size_t> RtestSession::indices_of(const std::string& setup) const {
  return where(samples, setup, [](const RtestSample& s) -> const std::string& { return s.setup; });
}

}  // namespace rotacal
