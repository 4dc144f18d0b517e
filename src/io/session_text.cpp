// SPDX-License-Identifier: BSD-3-Clause
// The writing shared by the session-file formats (session_text.hpp).
#include "session_text.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "strict_reader.hpp"

namespace rotacal {

std::string format_number(double v) {
  if (!std::isfinite(v))
    throw InvalidArgument("cannot write a non-finite number to a session file");
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  ROTACAL_ASSERT(r.ec == std::errc());
  return std::string(buf, r.ptr);
}

namespace io_detail {

std::string machine_lines(MachineType m) {
  std::string out = "# machine: " + to_string(m) + "\n";
  if (m != MachineType::AC_trt && m != MachineType::BC_trt)
    out += "# machine_description: " + machine_description_json(m.description()) + "\n";
  return out;
}

std::string rotary_header(MachineType m) {
  return std::string(1, m.description().axis(0).name) + "," + m.description().axis(1).name;
}
std::string rotary_values(MachineType m, double tilt_deg, double rot_deg) {
  const bool rot_first = m.rot_index() == 0;
  return format_number(rot_first ? rot_deg : tilt_deg) + "," +
         format_number(rot_first ? tilt_deg : rot_deg);
}

std::string vec_text(const Eigen::Vector3d& v) {
  return format_number(v.x()) + ", " + format_number(v.y()) + ", " + format_number(v.z());
}

void check_label(const std::string& label, const char* what) {
  if (label.empty() || label.find_first_of(",\n\r#") != std::string::npos || trim(label) != label)
    throw InvalidArgument(
        std::string(what) + " '" + label +
        "' cannot be written (empty, or contains a comma, '#', newline or edge spaces)");
}

void check_writable(double v, double lo, double hi, const char* what, std::size_t row) {
  if (!(v >= lo && v <= hi))
    throw InvalidArgument(std::string(what) + " " +
                          (std::isfinite(v) ? format_number(v) : std::string("non-finite")) +
                          " of sample " + std::to_string(row) + " is outside [" +
                          format_number(lo) + ", " + format_number(hi) +
                          "]: a file with it could not be read back");
}

void put(const std::unique_ptr<OutputStream>& f, const std::string& path, const std::string& text) {
  if (!f) throw IoError(path + ": writer is closed");
  f->write(text);
}
std::string annotation_line(const std::string& text) {
  std::string t = text;
  std::replace(t.begin(), t.end(), '\n', ' ');
  return "# " + trim(t) + "\n";
}

void end_stream(std::unique_ptr<OutputStream>& file, bool commit) {
  if (!file) return;
  std::unique_ptr<OutputStream> f = std::move(file);
  if (commit)
    f->commit();
  else
    f->discard();
}

}  // namespace io_detail
}  // namespace rotacal
