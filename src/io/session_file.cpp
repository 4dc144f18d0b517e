// rotacal-ballbar/1 and rotacal-rtest/1 session files: strict readers, exact writers, appending writers.
#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <string_view>
#include <unordered_map>
#include <sstream>

#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/io/output_file.hpp"
#include "text_reader.hpp"

namespace rotacal {

using namespace text_io;

namespace {

const char* kBallbarFormat = "rotacal-ballbar/1";
const char* kRtestFormat = "rotacal-rtest/1";

bool is_known_ballbar_key(const std::string& k) {
  return k == "format" || k == "machine" || k == "machine_description" || k == "units" ||
         k == "ballbar_length" || k == "pivot" || k == "noise_um";
}

bool is_known_rtest_key(const std::string& k) {
  return k == "format" || k == "machine" || k == "machine_description" || k == "units" ||
         k == "noise_um" || k.rfind("nest.", 0) == 0 ||
         (k.rfind("probe.", 0) == 0 && k.size() > 4 && k.compare(k.size() - 4, 4, ".dir") == 0);
}

std::string ballbar_head(const BallbarSession& s) {
  std::string out = std::string("# format: ") + kBallbarFormat + "\n";
  out += machine_lines(s.machine) + "# units: mm, deg, s\n";
  out += "# ballbar_length: " + format_number(s.ballbar_length) + "\n";
  out += "# pivot: " + vec_text(s.pivot) + "\n";
  if (s.noise_um) out += "# noise_um: " + format_number(*s.noise_um) + "\n";
  for (const auto& kv : s.metadata)
    if (!is_known_ballbar_key(kv.first)) out += "# " + kv.first + ": " + kv.second + "\n";
  out += "test,time,X,Y,Z," + rotary_header(s.machine) + ",length";
  for (const std::string& c : s.extra_columns) out += "," + c;
  return out + "\n";
}


std::string ballbar_row(const BallbarSample& r, MachineType m, std::size_t extra) {
  check_label(r.test, "test label");
  if (r.extra.size() != extra)
    throw InvalidArgument("sample has " + std::to_string(r.extra.size()) + " extra values for " +
                          std::to_string(extra) + " extra columns");
  std::string out = r.test + "," + format_number(r.time) + "," + format_number(r.xyz.x()) + "," +
                    format_number(r.xyz.y()) + "," + format_number(r.xyz.z()) + "," +
                    rotary_values(m, r.tilt_deg, r.rot_deg) + "," + format_number(r.length);
  for (const std::string& e : r.extra) out += "," + e;
  return out + "\n";
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
  std::string out = r.setup + "," + format_number(r.time) + "," + rotary_values(m, r.tilt_deg, r.rot_deg) +
                    "," + format_number(r.xyz.x()) + "," +
                    format_number(r.xyz.y()) + "," + format_number(r.xyz.z());
  auto add = [&](const std::optional<Eigen::Vector3d>& v, const char* names) {
    if (!v)
      throw InvalidArgument(std::string("R-test sample at time ") + format_number(r.time) + " has no " +
                            names + " values");
    out += "," + format_number(v->x()) + "," + format_number(v->y()) + "," + format_number(v->z());
  };
  if (cols.d) add(r.d, "dx,dy,dz");
  if (cols.raw) add(r.raw, "d1,d2,d3");
  for (const std::string& e : r.extra) out += "," + e;
  return out + "\n";
}


}  // namespace

std::string format_number(double v) {
  if (!std::isfinite(v)) throw InvalidArgument("cannot write a non-finite number to a session file");
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  ROTACAL_ASSERT(r.ec == std::errc());
  return std::string(buf, r.ptr);
}

// ---------------------------------------------------------------- ballbar

BallbarSession parse_ballbar(std::istream& in, const std::string& name) {
  Reader R;
  R.name = name;
  const RawFile raw = read_structure(in, R, kBallbarFormat);
  BallbarSession s;
  s.machine = read_machine(R);
  check_units(R);
  const std::string* L = R.meta("ballbar_length");
  if (!L) R.fail(0, 0, "missing metadata 'ballbar_length' (calibrated length L0, mm)");
  s.ballbar_length = R.meta_number("ballbar_length", *L, kMinLengthMm, kMaxLengthMm, "mm");
  if (!(s.ballbar_length > 0.0)) R.fail(R.meta_line("ballbar_length"), 0, "ballbar_length must be > 0");
  const std::string* P = R.meta("pivot");
  if (!P) R.fail(0, 0, "missing metadata 'pivot' (nominal centre-pivot position 'x, y, z', mm)");
  s.pivot = R.meta_vector("pivot", *P, kMaxAbsPositionMm, "mm");
  s.noise_um = read_noise(R);
  s.metadata = R.metadata;
  check_rotary_columns(R, s.machine);
  const std::string T(1, tilt_axis_letter(s.machine)), C(1, rot_axis_letter(s.machine));
  const int c_test = column_index(R, "test", true), c_time = column_index(R, "time", true),
            c_x = column_index(R, "X", true), c_y = column_index(R, "Y", true),
            c_z = column_index(R, "Z", true), c_t = column_index(R, T, true),
            c_c = column_index(R, C, true), c_len = column_index(R, "length", true);
  const std::set<int> known = {c_test, c_time, c_x, c_y, c_z, c_t, c_c, c_len};
  std::vector<int> extra_idx;
  for (int i = 0; i < static_cast<int>(R.header.size()); ++i)
    if (!known.count(i)) extra_idx.push_back(i), s.extra_columns.push_back(R.header[static_cast<std::size_t>(i)]);
  double last = -1e300;
  DuplicateRows dups;
  s.samples.reserve(raw.rows.size());
  for (const auto& row : raw.rows) {
    const std::vector<Field> f = row_fields(R, row);
    auto F = [&](int c) -> const Field& { return f[static_cast<std::size_t>(c)]; };
    BallbarSample b;
    b.test = R.label(F(c_test), "test label");
    b.time = R.bounded(F(c_time), "time", -kMaxAbsTimeS, kMaxAbsTimeS, "s");
    check_time(R, F(c_time), b.time, last);
    b.xyz = {R.bounded(F(c_x), "X", -kMaxAbsPositionMm, kMaxAbsPositionMm, "mm"),
             R.bounded(F(c_y), "Y", -kMaxAbsPositionMm, kMaxAbsPositionMm, "mm"),
             R.bounded(F(c_z), "Z", -kMaxAbsPositionMm, kMaxAbsPositionMm, "mm")};
    b.tilt_deg = R.bounded(F(c_t), T, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "deg");
    b.rot_deg = R.bounded(F(c_c), C, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "deg");
    const Field& fl = F(c_len);
    b.length = R.number(fl, "length");
    if (!(b.length > 0.0)) R.fail(R.line_no, fl.column, "length must be > 0");
    b.length = R.bounded(fl, "length", kMinLengthMm, kMaxLengthMm, "mm");
    dups.add(row, R.line_no, b.time);
    for (int i : extra_idx) b.extra.push_back(f[static_cast<std::size_t>(i)].text);
    s.samples.push_back(std::move(b));
  }
  s.annotations = annotations_of(raw);
  dups.report(s.warnings);
  return s;
}

BallbarSession read_ballbar(const std::string& path) {
  std::ifstream in = open_for_reading(path);
  return parse_ballbar(in, path);
}


std::string format_ballbar(const BallbarSession& s) {
  if (!(s.ballbar_length >= kMinLengthMm && s.ballbar_length <= kMaxLengthMm))
    throw InvalidArgument("ballbar_length must be within [0.001, 10000] mm");
  check_samples(s.samples);
  for (std::size_t i = 0; i < s.samples.size(); ++i)
    check_writable(s.samples[i].length, kMinLengthMm, kMaxLengthMm, "length", i);
  return ballbar_head(s) + with_annotations(s.samples, s.annotations, [&](const BallbarSample& r) {
           return ballbar_row(r, s.machine, s.extra_columns.size());
         });
}

void write_ballbar(const BallbarSession& s, const std::string& path) {
  write_output(path, format_ballbar(s));
}

// ---------------------------------------------------------------- R-test

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
        R.fail(R.meta_line(kv.first), 0, kv.first + " must be a unit vector (norm " + format_number(d.norm()) + ")");
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
  const int n_d = (c_dx >= 0) + (c_dy >= 0) + (c_dz >= 0), n_raw = (c_d1 >= 0) + (c_d2 >= 0) + (c_d3 >= 0);
  if (n_d != 0 && n_d != 3) R.fail(R.header_line, 0, "dx, dy, dz must come together");
  if (n_raw != 0 && n_raw != 3) R.fail(R.header_line, 0, "d1, d2, d3 must come together");
  if (n_d == 0 && n_raw == 0)
    R.fail(R.header_line, 0, "missing required columns: either dx,dy,dz or d1,d2,d3");
  if (n_raw == 3)
    for (int k = 1; k <= 3; ++k)
      if (!s.probe_dirs.count(k))
        R.fail(0, 0, "raw columns d1,d2,d3 need metadata 'probe." + std::to_string(k) + ".dir'");
  const std::set<int> known = {c_setup, c_time, c_t, c_c, c_x, c_y, c_z, c_dx, c_dy, c_dz, c_d1, c_d2, c_d3};
  std::vector<int> extra_idx;
  for (int i = 0; i < static_cast<int>(R.header.size()); ++i)
    if (!known.count(i)) extra_idx.push_back(i), s.extra_columns.push_back(R.header[static_cast<std::size_t>(i)]);
  double last = -1e300;
  DuplicateRows dups;
  for (const auto& row : raw.rows) {
    const std::vector<Field> f = row_fields(R, row);
    auto F = [&](int c) -> const Field& { return f[static_cast<std::size_t>(c)]; };
    RtestSample r;
    r.setup = R.label(F(c_setup), "setup label");
    if (!s.nests.count(r.setup))
      R.fail(R.line_no, F(c_setup).column, "setup '" + excerpt(r.setup) + "' has no 'nest." + excerpt(r.setup) + "' metadata");
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
  if (!cols.d && !cols.raw) throw InvalidArgument("R-test session has neither dx,dy,dz nor d1,d2,d3 values");
  check_samples(s.samples);
  for (const RtestSample& r : s.samples) {
    for (const auto* v : {&r.d, &r.raw})
      if (*v)
        for (int k = 0; k < 3; ++k)
          check_writable((**v)[k], -kMaxAbsDisplacementMm, kMaxAbsDisplacementMm, "displacement", 0);
    if (!s.nests.count(r.setup)) throw InvalidArgument("setup '" + r.setup + "' has no nest in the session");
    if (r.d.has_value() != cols.d || r.raw.has_value() != cols.raw)
      throw InvalidArgument("every R-test sample must carry the same columns (dx,dy,dz and/or d1,d2,d3)");
  }
  return rtest_head(s, cols) + with_annotations(s.samples, s.annotations, [&](const RtestSample& r) {
           return rtest_row(r, s.machine, cols, s.extra_columns.size());
         });
}

void write_rtest(const RtestSession& s, const std::string& path) { write_output(path, format_rtest(s)); }

AnySession read_session(const std::string& path) {
  std::ifstream in = open_for_reading(path);
  return text_io::read_sniffed_session(in, path, sniff_format_line(in, path));
}

AnySession text_io::read_sniffed_session(std::ifstream& in, const std::string& path, const FormatLine& sniffed) {
  const std::string &head = sniffed.head, &line = sniffed.line;
  const std::string t = trim(line);
  if (t.find(kRtestFormat) != std::string::npos) return parse_rtest(in, path);
  // Anything but a plain-text first line (binary data, no line end in 4 kB, not UTF-8) gets
  // the ballbar reader's precise message (line, column, byte).
  const bool plain = head.find('\n') != std::string::npos &&
                     std::all_of(line.begin(), line.end(), [](char c) {
                       const unsigned char u = static_cast<unsigned char>(c);
                       return (u >= 0x20 && u < 0x7F) || u == '\t' || u == '\r';
                     });
  if (t.find(kBallbarFormat) != std::string::npos || t.empty() || !plain) return parse_ballbar(in, path);
  throw ParseError(path, 1, 1, std::string("first line must be '# format: ") + kBallbarFormat + "' or '# format: " +
                                   kRtestFormat + "', got '" + excerpt(t) + "'");
}

// ---------------------------------------------------------------- appending writers

namespace {
void put(const std::unique_ptr<OutputStream>& f, const std::string& path, const std::string& text) {
  if (!f) throw IoError(path + ": writer is closed");
  f->write(text);
}
std::string annotation_line(const std::string& text) {
  std::string t = text;
  std::replace(t.begin(), t.end(), '\n', ' ');
  return "# " + trim(t) + "\n";
}
}  // namespace

BallbarWriter::BallbarWriter(const std::string& path, const BallbarSession& header, const OutputOptions& options)
    : file_(std::make_unique<OutputStream>(path, options)), path_(path), machine_(header.machine),
      columns_(header.extra_columns.size()) {
  file_->write(ballbar_head(header));
}
void BallbarWriter::append(const BallbarSample& s) {
  if (s.time < last_time_) throw InvalidArgument(path_ + ": sample time " + format_number(s.time) + " goes backwards");
  put(file_, path_, ballbar_row(s, machine_, columns_));
  last_time_ = s.time;
  ++rows_;
}
void BallbarWriter::annotate(const std::string& text) { put(file_, path_, annotation_line(text)); }
void BallbarWriter::close() {
  if (!file_) return;
  std::unique_ptr<OutputStream> f = std::move(file_);
  f->commit();
}
void BallbarWriter::discard() {
  if (!file_) return;
  std::unique_ptr<OutputStream> f = std::move(file_);
  f->discard();
}

RtestWriter::RtestWriter(const std::string& path, const RtestSession& header, bool raw, const OutputOptions& options)
    : path_(path), machine_(header.machine), raw_(raw), extra_(header.extra_columns.size()) {
  if (raw)
    for (int k = 1; k <= 3; ++k)
      if (!header.probe_dirs.count(k))
        throw InvalidArgument("RtestWriter: raw columns need probe." + std::to_string(k) + ".dir");
  file_ = std::make_unique<OutputStream>(path, options);
  file_->write(rtest_head(header, RtestColumns{!raw, raw}));
}
void RtestWriter::append(const RtestSample& s) {
  if (s.time < last_time_) throw InvalidArgument(path_ + ": sample time " + format_number(s.time) + " goes backwards");
  put(file_, path_, rtest_row(s, machine_, RtestColumns{!raw_, raw_}, extra_));
  last_time_ = s.time;
  ++rows_;
}
void RtestWriter::annotate(const std::string& text) { put(file_, path_, annotation_line(text)); }
void RtestWriter::close() {
  if (!file_) return;
  std::unique_ptr<OutputStream> f = std::move(file_);
  f->commit();
}
void RtestWriter::discard() {
  if (!file_) return;
  std::unique_ptr<OutputStream> f = std::move(file_);
  f->discard();
}

}  // namespace rotacal
