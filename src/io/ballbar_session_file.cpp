// SPDX-License-Identifier: BSD-3-Clause
// rotacal-ballbar/1 session files: the strict reader, the exact writer, the appending writer.
#include <set>

#include "rotacal/io/ballbar_file.hpp"
#include "session_text.hpp"
#include "strict_reader.hpp"

namespace rotacal {

using namespace io_detail;

namespace {

bool is_known_ballbar_key(const std::string& k) {
  return k == "format" || k == "machine" || k == "machine_description" || k == "units" ||
         k == "ballbar_length" || k == "pivot" || k == "noise_um";
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

}  // namespace

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
  if (!(s.ballbar_length > 0.0))
    R.fail(R.meta_line("ballbar_length"), 0, "ballbar_length must be > 0");
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
    if (!known.count(i))
      extra_idx.push_back(i), s.extra_columns.push_back(R.header[static_cast<std::size_t>(i)]);
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

BallbarWriter::BallbarWriter(const std::string& path, const BallbarSession& header,
                             const OutputOptions& options)
    : file_(std::make_unique<OutputStream>(path, options)),
      path_(path),
      machine_(header.machine),
      columns_(header.extra_columns.size()) {
  file_->write(ballbar_head(header));
}
void BallbarWriter::append(const BallbarSample& s) {
  if (s.time < last_time_)
    throw InvalidArgument(path_ + ": sample time " + format_number(s.time) + " goes backwards");
  put(file_, path_, ballbar_row(s, machine_, columns_));
  last_time_ = s.time;
  ++rows_;
}
void BallbarWriter::annotate(const std::string& text) { put(file_, path_, annotation_line(text)); }
void BallbarWriter::close() { end_stream(file_, true); }
void BallbarWriter::discard() { end_stream(file_, false); }

}  // namespace rotacal
