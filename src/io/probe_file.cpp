// SPDX-License-Identifier: BSD-3-Clause
// rotacal-probe/1 session files: strict reader, exact writer (formats.md, "Touch-probe session").
#include "rotacal/io/probe_file.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <set>

#include "rotacal/io/output_file.hpp"
#include "rotacal/session/thermal_test.hpp"
#include "session_text.hpp"
#include "strict_reader.hpp"

namespace rotacal {

using namespace io_detail;

namespace {

const char* kProbeFormat = "rotacal-probe/1";

bool is_known_probe_key(const std::string& k) {
  return k == "format" || k == "machine" || k == "machine_description" || k == "units" ||
         k == "sphere" || k == "sphere_diameter" || k == "stylus_diameter" || k == "noise_um";
}

std::string probe_head(const ProbeSession& s) {
  std::string out = std::string("# format: ") + kProbeFormat + "\n";
  out += machine_lines(s.machine) + "# units: mm, deg, s\n";
  out += "# sphere: " + vec_text(s.sphere) + "\n";
  out += "# sphere_diameter: " + format_number(s.sphere_diameter) + "\n";
  out += "# stylus_diameter: " + format_number(s.stylus_diameter) + "\n";
  if (s.noise_um) out += "# noise_um: " + format_number(*s.noise_um) + "\n";
  for (const auto& kv : s.metadata)
    if (!is_known_probe_key(kv.first)) out += "# " + kv.first + ": " + kv.second + "\n";
  out += "pose,time,X,Y,Z," + rotary_header(s.machine) + ",nx,ny,nz";
  for (const std::string& c : s.extra_columns) out += "," + c;
  return out + "\n";
}

std::string probe_row(const ProbeSample& r, MachineType m, std::size_t extra) {
  check_label(r.pose, "pose label");
  if (r.extra.size() != extra)
    throw InvalidArgument("touch at time " + format_number(r.time) + " has " +
                          std::to_string(r.extra.size()) + " extra values for " +
                          std::to_string(extra) + " extra columns");
  std::string out = r.pose + "," + format_number(r.time) + "," + format_number(r.xyz.x()) + "," +
                    format_number(r.xyz.y()) + "," + format_number(r.xyz.z()) + "," +
                    rotary_values(m, r.tilt_deg, r.rot_deg) + "," + format_number(r.n.x()) + "," +
                    format_number(r.n.y()) + "," + format_number(r.n.z());
  for (const std::string& e : r.extra) out += "," + e;
  return out + "\n";
}

// The metadata of a probe file: sphere, its diameter and the stylus', all required.
void read_probe_metadata(const Reader& R, ProbeSession& s) {
  const std::string* c = R.meta("sphere");
  if (!c)
    R.fail(0, 0,
           "missing metadata 'sphere' (nominal sphere centre 'x, y, z' in the table frame, mm)");
  s.sphere = R.meta_vector("sphere", *c, kMaxAbsPositionMm, "mm");
  const std::string* D = R.meta("sphere_diameter");
  if (!D)
    R.fail(0, 0, "missing metadata 'sphere_diameter' (calibrated diameter of the sphere, mm)");
  s.sphere_diameter = R.meta_number("sphere_diameter", *D, 0.0, kMaxProbeDiameterMm, "mm");
  if (!(s.sphere_diameter > 0.0))
    R.fail(R.meta_line("sphere_diameter"), 0, "sphere_diameter must be > 0");
  const std::string* d = R.meta("stylus_diameter");
  if (!d)
    R.fail(0, 0, "missing metadata 'stylus_diameter' (effective diameter of the stylus tip, mm)");
  s.stylus_diameter = R.meta_number("stylus_diameter", *d, 0.0, kMaxProbeDiameterMm, "mm");
}

}  // namespace

ProbeSession parse_probe(std::istream& in, const std::string& name) {
  Reader R;
  R.name = name;
  const RawFile raw = read_structure(in, R, kProbeFormat);
  ProbeSession s;
  s.machine = read_machine(R);
  check_units(R);
  read_probe_metadata(R, s);
  s.noise_um = read_noise(R);
  s.metadata = R.metadata;
  check_rotary_columns(R, s.machine);
  const std::string T(1, tilt_axis_letter(s.machine)), C(1, rot_axis_letter(s.machine));
  const int c_pose = column_index(R, "pose", true), c_time = column_index(R, "time", true),
            c_x = column_index(R, "X", true), c_y = column_index(R, "Y", true),
            c_z = column_index(R, "Z", true), c_t = column_index(R, T, true),
            c_c = column_index(R, C, true), c_nx = column_index(R, "nx", true),
            c_ny = column_index(R, "ny", true), c_nz = column_index(R, "nz", true);
  const std::set<int> known = {c_pose, c_time, c_x, c_y, c_z, c_t, c_c, c_nx, c_ny, c_nz};
  std::vector<int> extra_idx;
  for (int i = 0; i < static_cast<int>(R.header.size()); ++i)
    if (!known.count(i))
      extra_idx.push_back(i), s.extra_columns.push_back(R.header[static_cast<std::size_t>(i)]);
  double last = -1e300;
  DuplicateRows dups;
  std::map<std::string, std::pair<int, Eigen::Vector2d>>
      pose_at;  // first line and angles of each pose
  s.samples.reserve(raw.rows.size());
  for (const auto& row : raw.rows) {
    const std::vector<Field> f = row_fields(R, row);
    auto F = [&](int c) -> const Field& { return f[static_cast<std::size_t>(c)]; };
    const auto pos = [&](int c, const char* what) {
      return R.bounded(F(c), what, -kMaxAbsPositionMm, kMaxAbsPositionMm, "mm");
    };
    ProbeSample p;
    p.pose = R.label(F(c_pose), "pose label");
    p.time = R.bounded(F(c_time), "time", -kMaxAbsTimeS, kMaxAbsTimeS, "s");
    check_time(R, F(c_time), p.time, last);
    p.xyz = {pos(c_x, "X"), pos(c_y, "Y"), pos(c_z, "Z")};
    p.tilt_deg = R.bounded(F(c_t), T, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "deg");
    p.rot_deg = R.bounded(F(c_c), C, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "deg");
    const Eigen::Vector3d n(R.bounded(F(c_nx), "nx", -2.0, 2.0, ""),
                            R.bounded(F(c_ny), "ny", -2.0, 2.0, ""),
                            R.bounded(F(c_nz), "nz", -2.0, 2.0, ""));
    if (!(std::abs(n.norm() - 1.0) <= kMaxDirectionNormError))
      R.fail(R.line_no, F(c_nx).column,
             "approach direction nx, ny, nz has norm " + format_number(n.norm()) +
                 " (must be 1 within 1e-4)");
    // Normalised, but a vector already of unit norm to rounding is kept as read: renormalising
    // it can move its last bit, and what format_probe writes must read back identical (found by
    // fuzz_file_readers). After normalising, | |n|^2 - 1 | was at most 3 eps in 2e6 random
    // directions, so the 8 eps here keeps every written direction.
    p.n = std::abs(n.squaredNorm() - 1.0) <= 8.0 * std::numeric_limits<double>::epsilon()
              ? n
              : n.normalized();
    const Eigen::Vector2d angles(p.tilt_deg, p.rot_deg);
    const auto seen = pose_at.emplace(p.pose, std::make_pair(R.line_no, angles));
    if (!seen.second && (seen.first->second.second - angles).cwiseAbs().maxCoeff() > 1e-9)
      R.fail(R.line_no, F(c_t).column,
             "pose '" + excerpt(p.pose) + "' is held at one rotary position, but its " + T + ", " +
                 C + " differ from line " + std::to_string(seen.first->second.first) + "'s");
    dups.add(row, R.line_no, p.time);
    for (int i : extra_idx) p.extra.push_back(F(i).text);
    s.samples.push_back(std::move(p));
  }
  s.annotations = annotations_of(raw);
  dups.report(s.warnings);
  for (const auto& kv : s.metadata)  // formats.md, thermal test: pooled, but it drifts
    if (is_duty_key(kv.first)) {
      s.warnings.push_back(kThermalSessionPooled);
      break;
    }
  return s;
}

ProbeSession read_probe(const std::string& path) {
  std::ifstream in = open_for_reading(path);
  return parse_probe(in, path);
}

std::string format_probe(const ProbeSession& s) {
  if (!(s.sphere_diameter > 0.0 && s.sphere_diameter <= kMaxProbeDiameterMm))
    throw InvalidArgument("sphere_diameter must be within (0, 1000] mm");
  if (!(s.stylus_diameter >= 0.0 && s.stylus_diameter <= kMaxProbeDiameterMm))
    throw InvalidArgument("stylus_diameter must be within [0, 1000] mm");
  for (int k = 0; k < 3; ++k)
    check_writable(s.sphere[k], -kMaxAbsPositionMm, kMaxAbsPositionMm, "sphere", 0);
  check_samples(s.samples);
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    check_writable(s.samples[i].n.norm(), 1.0 - kMaxDirectionNormError,
                   1.0 + kMaxDirectionNormError, "approach direction norm", i);
  return probe_head(s) + with_annotations(s.samples, s.annotations, [&](const ProbeSample& r) {
           return probe_row(r, s.machine, s.extra_columns.size());
         });
}

void write_probe(const ProbeSession& s, const std::string& path) {
  write_output(path, format_probe(s));
}

InstrumentSession read_instrument_session(const std::string& path) {
  std::ifstream in = open_for_reading(path);
  const FormatLine sniffed = sniff_format_line(in, path);
  if (trim(sniffed.line).find(kProbeFormat) != std::string::npos) return parse_probe(in, path);
  return std::visit([](auto&& s) -> InstrumentSession { return std::move(s); },
                    read_sniffed_session(in, path, sniffed));
}

}  // namespace rotacal
