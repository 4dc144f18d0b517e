// SPDX-License-Identifier: BSD-3-Clause
// Sessions to and from numpy-shaped columns, validated as the file reader validates them.
#include "rotacal/io/session_arrays.hpp"

#include <cmath>

#include "rotacal/io/ballbar_file.hpp"

namespace rotacal {

namespace {
template <typename Sample, typename Get>
Eigen::VectorXd column(const std::vector<Sample>& v, Get get) {
  Eigen::VectorXd out(static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) out[static_cast<Eigen::Index>(i)] = get(v[i]);
  return out;
}
void check_rows(Eigen::Index n, Eigen::Index expected, const char* name) {
  if (n != expected)
    throw InvalidArgument(std::string(name) + ": " + std::to_string(n) + " rows, expected " +
                          std::to_string(expected));
}
template <typename M>
void check_finite(const M& m, const char* name) {
  if (!m.allFinite()) throw InvalidArgument(std::string(name) + " contains NaN or infinity");
}
// The file reader's limits (ballbar_file.hpp), so a session built from arrays is one that
// `save` can write and `load` read back.
template <typename M>
void check_range(const M& m, const char* name, double lo, double hi, const char* unit) {
  for (Eigen::Index i = 0; i < m.size(); ++i)
    if (!(m.data()[i] >= lo && m.data()[i] <= hi))
      throw InvalidArgument(std::string(name) + ": " + format_number(m.data()[i]) + " (entry " +
                            std::to_string(i) + ") is outside [" + format_number(lo) + ", " +
                            format_number(hi) + "] " + unit);
}
}  // namespace

std::vector<std::string> ballbar_tests(const BallbarSession& s) {
  std::vector<std::string> out;
  for (const auto& b : s.samples) out.push_back(b.test);
  return out;
}
Eigen::VectorXd ballbar_times(const BallbarSession& s) {
  return column(s.samples, [](const BallbarSample& b) { return b.time; });
}
Eigen::VectorXd ballbar_lengths(const BallbarSession& s) {
  return column(s.samples, [](const BallbarSample& b) { return b.length; });
}
RowMatrix3 ballbar_xyz(const BallbarSession& s) {
  RowMatrix3 m(static_cast<Eigen::Index>(s.samples.size()), 3);
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    m.row(static_cast<Eigen::Index>(i)) = s.samples[i].xyz;
  return m;
}
RowMatrix2 ballbar_angles_deg(const BallbarSession& s) {
  RowMatrix2 m(static_cast<Eigen::Index>(s.samples.size()), 2);
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    m.row(static_cast<Eigen::Index>(i)) << s.samples[i].tilt_deg, s.samples[i].rot_deg;
  return m;
}

BallbarSession make_ballbar_session(MachineType machine, double ballbar_length,
                                    const Eigen::Vector3d& pivot,
                                    const std::vector<std::string>& tests,
                                    const Eigen::VectorXd& time, const RowMatrix3& xyz,
                                    const RowMatrix2& angles_deg, const Eigen::VectorXd& length,
                                    std::optional<double> noise_um) {
  const auto n = static_cast<Eigen::Index>(tests.size());
  check_rows(time.size(), n, "time");
  check_rows(xyz.rows(), n, "xyz");
  check_rows(angles_deg.rows(), n, "angles_deg");
  check_rows(length.size(), n, "length");
  check_finite(time, "time");
  check_finite(xyz, "xyz");
  check_finite(angles_deg, "angles_deg");
  check_finite(length, "length");
  check_finite(pivot, "pivot");
  if (!(ballbar_length >= kMinLengthMm && ballbar_length <= kMaxLengthMm))
    throw InvalidArgument("ballbar_length must be finite and within [0.001, 10000] mm");
  if (noise_um && !(*noise_um > 0.0 && *noise_um <= kMaxNoiseUm))
    throw InvalidArgument("noise_um must be > 0 and <= 1e5");
  check_range(time, "time", -kMaxAbsTimeS, kMaxAbsTimeS, "s");
  check_range(xyz, "xyz", -kMaxAbsPositionMm, kMaxAbsPositionMm, "mm");
  check_range(angles_deg, "angles_deg", -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "deg");
  check_range(length, "length", kMinLengthMm, kMaxLengthMm, "mm");
  check_range(pivot, "pivot", -kMaxAbsPositionMm, kMaxAbsPositionMm, "mm");
  BallbarSession s;
  s.machine = machine;
  s.ballbar_length = ballbar_length;
  s.pivot = pivot;
  s.noise_um = noise_um;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (i > 0 && time[i] < time[i - 1])
      throw InvalidArgument("time decreases at row " + std::to_string(i));
    if (tests[static_cast<std::size_t>(i)].empty())
      throw InvalidArgument("tests: empty label at row " + std::to_string(i));
    if (tests[static_cast<std::size_t>(i)].size() > kMaxLabelBytes)
      throw InvalidArgument("tests: label at row " + std::to_string(i) +
                            " is longer than 256 bytes");
    BallbarSample b;
    b.test = tests[static_cast<std::size_t>(i)];
    b.time = time[i];
    b.xyz = xyz.row(i).transpose();
    b.tilt_deg = angles_deg(i, 0);
    b.rot_deg = angles_deg(i, 1);
    b.length = length[i];
    s.samples.push_back(b);
  }
  return s;
}

BallbarSession with_lengths(const BallbarSession& s, const Eigen::VectorXd& length) {
  check_rows(length.size(), static_cast<Eigen::Index>(s.samples.size()), "length");
  check_finite(length, "length");
  BallbarSession out = s;
  for (std::size_t i = 0; i < out.samples.size(); ++i)
    out.samples[i].length = length[static_cast<Eigen::Index>(i)];
  return out;
}

std::vector<std::string> rtest_setups(const RtestSession& s) {
  std::vector<std::string> out;
  for (const auto& r : s.samples) out.push_back(r.setup);
  return out;
}
Eigen::VectorXd rtest_times(const RtestSession& s) {
  return column(s.samples, [](const RtestSample& r) { return r.time; });
}
RowMatrix2 rtest_angles_deg(const RtestSession& s) {
  RowMatrix2 m(static_cast<Eigen::Index>(s.samples.size()), 2);
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    m.row(static_cast<Eigen::Index>(i)) << s.samples[i].tilt_deg, s.samples[i].rot_deg;
  return m;
}
RowMatrix3 rtest_xyz(const RtestSession& s) {
  RowMatrix3 m(static_cast<Eigen::Index>(s.samples.size()), 3);
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    m.row(static_cast<Eigen::Index>(i)) = s.samples[i].xyz;
  return m;
}
RowMatrix3 rtest_displacements(const RtestSession& s) {
  RowMatrix3 m(static_cast<Eigen::Index>(s.samples.size()), 3);
  for (std::size_t i = 0; i < s.samples.size(); ++i) {
    if (!s.samples[i].d)
      throw InvalidArgument(
          "R-test session has no dx,dy,dz (raw probe readings only: convert them "
          "with a probe calibration first)");
    m.row(static_cast<Eigen::Index>(i)) = *s.samples[i].d;
  }
  return m;
}
RtestSession with_displacements(const RtestSession& s, const RowMatrix3& d) {
  check_rows(d.rows(), static_cast<Eigen::Index>(s.samples.size()), "d");
  check_finite(d, "d");
  RtestSession out = s;
  for (std::size_t i = 0; i < out.samples.size(); ++i)
    out.samples[i].d = d.row(static_cast<Eigen::Index>(i)).transpose();
  return out;
}

}  // namespace rotacal
