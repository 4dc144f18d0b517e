// SPDX-License-Identifier: BSD-3-Clause
// rotacal-rtest/1 session files: the strict reader, the exact writer, the appending writer.
#include <set>

#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/session/thermal_test.hpp"
#include "session_text.hpp"
#include "strict_reader.hpp"

namespace rotacal {

using namespace io_detail;

namespace {

bool is_known_rtest_key(const std::string& k) {
  return k == "format" || k == "machine" || k == "machine_description" || k == "units" ||
         k == "noise_um" || k.rfind("nest.", 0) == 0 ||
         (k.rfind("probe.", 0) == 0 && k.size() > 4 && k.compare(k.size() - 4, 4, ".dir") == 0);
}

// Which displacement columns an R-test file carries.
struct RtestColumns {
  bool d = true;     // dx,dy,dz
  bool raw = false;  // d1,d2,d3
};

std::string rtest_head(const RtestSession& s, RtestColumns cols) {
  std::string out = std::string("# format: ") + kRtestFormat + "\n";
  out += machine_lines(s.machine) + "# units: mm, deg, s\n";
  for (const auto& n : s.nests) out += "# nest." + n.first + ": " + vec_text(n.second) + "\n";
  for (const auto& p : s.probe_dirs)
    out += "# probe." + std::to_string(p.first) + ".dir: " + vec_text(p.second) + "\n";
  if (s.noise_um) out += "# noise_um: " + format_number(*s.noise_um) + "\n";
  for (const auto& kv : s.metadata)
    if (!is_known_rtest_key(kv.first)) out += "# " + kv.first + ": " + kv.second + "\n";
  out += "setup,time," + rotary_header(s.machine) + ",X,Y,Z";
  if (cols.d) out += ",dx,dy,dz";
  if (cols.raw) out += ",d1,d2,d3";
  for (const std::string& c : s.extra_columns) out += "," + c;
  return out + "\n";
}

std::string rtest_row(const RtestSample& r, MachineType m, RtestColumns cols, std::size_t extra) {
  check_label(r.setup, "setup label");
  if (r.extra.size() != extra) throw InvalidArgument("R-test sample: wrong number of extra values");
  std::string out = r.setup + "," + format_number(r.time) + "," +
                    rotary_values(m, r.tilt_deg, r.rot_deg) + "," + format_number(r.xyz.x()) + "," +
                    format_number(r.xyz.y()) + "," + format_number(r.xyz.z());
  auto add = [&](const std::optional<Eigen::Vector3d>& v, const char* names) {
    if (!v)
      throw InvalidArgument(std::string("R-test sample at time ") + format_number(r.time) +
                            " has no " + names + " values");
    out += "," + format_number(v->x()) + "," + format_number(v->y()) + "," + format_number(v->z());
  };
  if (cols.d) add(r.d, "dx,dy,dz");
  if (cols.raw) add(r.raw, "d1,d2,d3");
  for (const std::string& e : r.extra) out += "," + e;
  return out + "\n";
}

}  // namespace

RtestSession parse_rtest(std::istream& in, const std::string& name) {
  Reader R;
  R.name = name;
  const RawFile raw = read_structure(in, R, kRtestFormat);
  RtestSession s;
  s.machine = read_machine(R);
  check_units(R);
  s.noise_um = read_noise(R);
  for (const auto& kv : R.metadata) {
    if (kv.first.rfind("nest.", 0) == 0) {
      const std::string label = kv.first.substr(5);
      if (label.empty()) R.fail(R.meta_line(kv.first), 0, "nest metadata needs a label: 'nest.N'");
      s.nests[label] = R.meta_vector(kv.first, kv.second, kMaxAbsPositionMm, "mm");
    } else if (kv.first.rfind("probe.", 0) == 0 && kv.first.size() > 10 &&
               kv.first.compare(kv.first.size() - 4, 4, ".dir") == 0) {
      const std::string n = kv.first.substr(6, kv.first.size() - 10);
      if (n != "1" && n != "2" && n != "3")
        R.fail(R.meta_line(kv.first), 0, "probe number must be 1, 2 or 3 in '" + kv.first + "'");
      const Eigen::Vector3d d = R.meta_vector(kv.first, kv.second, 2.0, "");
      if (std::abs(d.norm() - 1.0) > 1e-6)
        R.fail(R.meta_line(kv.first), 0,
               kv.first + " must be a unit vector (norm " + format_number(d.norm()) + ")");
      s.probe_dirs[std::stoi(n)] = d;
    }
  }
  s.metadata = R.metadata;
  check_rotary_columns(R, s.machine);
  const std::string T(1, tilt_axis_letter(s.machine)), C(1, rot_axis_letter(s.machine));
  const int c_setup = column_index(R, "setup", true), c_time = column_index(R, "time", true),
            c_t = column_index(R, T, true), c_c = column_index(R, C, true),
            c_x = column_index(R, "X", true), c_y = column_index(R, "Y", true),
            c_z = column_index(R, "Z", true);
  const int c_dx = column_index(R, "dx", false), c_dy = column_index(R, "dy", false),
            c_dz = column_index(R, "dz", false);
  const int c_d1 = column_index(R, "d1", false), c_d2 = column_index(R, "d2", false),
            c_d3 = column_index(R, "d3", false);
  const int n_d = (c_dx >= 0) + (c_dy >= 0) + (c_dz >= 0),
            n_raw = (c_d1 >= 0) + (c_d2 >= 0) + (c_d3 >= 0);
  if (n_d != 0 && n_d != 3) R.fail(R.header_line, 0, "dx, dy, dz must come together");
  if (n_raw != 0 && n_raw != 3) R.fail(R.header_line, 0, "d1, d2, d3 must come together");
  if (n_d == 0 && n_raw == 0)
    R.fail(R.header_line, 0, "missing required columns: either dx,dy,dz or d1,d2,d3");
  if (n_raw == 3)
    for (int k = 1; k <= 3; ++k)
      if (!s.probe_dirs.count(k))
        R.fail(0, 0, "raw columns d1,d2,d3 need metadata 'probe." + std::to_string(k) + ".dir'");
  const std::set<int> known = {c_setup, c_time, c_t,  c_c,  c_x,  c_y, c_z,
                               c_dx,    c_dy,   c_dz, c_d1, c_d2, c_d3};
  std::vector<int> extra_idx;
  for (int i = 0; i < static_cast<int>(R.header.size()); ++i)
    if (!known.count(i))
      extra_idx.push_back(i), s.extra_columns.push_back(R.header[static_cast<std::size_t>(i)]);
  double last = -1e300;
  DuplicateRows dups;
  for (const auto& row : raw.rows) {
    const std::vector<Field> f = row_fields(R, row);
    auto F = [&](int c) -> const Field& { return f[static_cast<std::size_t>(c)]; };
    RtestSample r;
    r.setup = R.label(F(c_setup), "setup label");
    if (!s.nests.count(r.setup))
      R.fail(R.line_no, F(c_setup).column,
             "setup '" + excerpt(r.setup) + "' has no 'nest." + excerpt(r.setup) + "' metadata");
    const auto pos = [&](int c, const char* what) {
      return R.bounded(F(c), what, -kMaxAbsPositionMm, kMaxAbsPositionMm, "mm");
    };
    const auto disp = [&](int c, const char* what) {
      return R.bounded(F(c), what, -kMaxAbsDisplacementMm, kMaxAbsDisplacementMm, "mm");
    };
    r.time = R.bounded(F(c_time), "time", -kMaxAbsTimeS, kMaxAbsTimeS, "s");
    check_time(R, F(c_time), r.time, last);
    r.tilt_deg = R.bounded(F(c_t), T, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "deg");
    r.rot_deg = R.bounded(F(c_c), C, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "deg");
    r.xyz = {pos(c_x, "X"), pos(c_y, "Y"), pos(c_z, "Z")};
    if (n_d == 3) r.d = Eigen::Vector3d(disp(c_dx, "dx"), disp(c_dy, "dy"), disp(c_dz, "dz"));
    if (n_raw == 3) r.raw = Eigen::Vector3d(disp(c_d1, "d1"), disp(c_d2, "d2"), disp(c_d3, "d3"));
    dups.add(row, R.line_no, r.time);
    for (int i : extra_idx) r.extra.push_back(F(i).text);
    s.samples.push_back(std::move(r));
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

RtestSession read_rtest(const std::string& path) {
  std::ifstream in = open_for_reading(path);
  return parse_rtest(in, path);
}

std::string format_rtest(const RtestSession& s) {
  RtestColumns cols;
  cols.d = !s.samples.empty() && s.samples.front().d.has_value();
  cols.raw = !s.samples.empty() && s.samples.front().raw.has_value();
  if (!cols.d && !cols.raw)
    throw InvalidArgument("R-test session has neither dx,dy,dz nor d1,d2,d3 values");
  check_samples(s.samples);
  for (const RtestSample& r : s.samples) {
    for (const auto* v : {&r.d, &r.raw})
      if (*v)
        for (int k = 0; k < 3; ++k)
          check_writable((**v)[k], -kMaxAbsDisplacementMm, kMaxAbsDisplacementMm, "displacement",
                         0);
    if (!s.nests.count(r.setup))
      throw InvalidArgument("setup '" + r.setup + "' has no nest in the session");
    if (r.d.has_value() != cols.d || r.raw.has_value() != cols.raw)
      throw InvalidArgument(
          "every R-test sample must carry the same columns (dx,dy,dz and/or d1,d2,d3)");
  }
  return rtest_head(s, cols) +
         with_annotations(s.samples, s.annotations, [&](const RtestSample& r) {
           return rtest_row(r, s.machine, cols, s.extra_columns.size());
         });
}

void write_rtest(const RtestSession& s, const std::string& path) {
  write_output(path, format_rtest(s));
}

RtestWriter::RtestWriter(const std::string& path, const RtestSession& header, bool raw,
                         const OutputOptions& options)
    : path_(path), machine_(header.machine), raw_(raw), extra_(header.extra_columns.size()) {
  if (raw)
    for (int k = 1; k <= 3; ++k)
      if (!header.probe_dirs.count(k))
        throw InvalidArgument("RtestWriter: raw columns need probe." + std::to_string(k) + ".dir");
  file_ = std::make_unique<OutputStream>(path, options);
  file_->write(rtest_head(header, RtestColumns{!raw, raw}));
}
void RtestWriter::append(const RtestSample& s) {
  if (s.time < last_time_)
    throw InvalidArgument(path_ + ": sample time " + format_number(s.time) + " goes backwards");
  put(file_, path_, rtest_row(s, machine_, RtestColumns{!raw_, raw_}, extra_));
  last_time_ = s.time;
  ++rows_;
}
void RtestWriter::annotate(const std::string& text) { put(file_, path_, annotation_line(text)); }
void RtestWriter::close() { end_stream(file_, true); }
void RtestWriter::discard() { end_stream(file_, false); }

}  // namespace rotacal
