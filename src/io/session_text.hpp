// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The writing shared by the session-file formats: machine and rotary columns of a header, a
// sample's rotary values, labels and values checked so that no file is written that the
// strict reader (strict_reader.hpp) would refuse, annotations between rows, and the output
// stream of the appending writers.
#include <memory>
#include <string>
#include <vector>

#include "rotacal/io/ballbar_file.hpp"

namespace rotacal::io_detail {

// The machine lines of a header: the name, and for every machine but the two tables that
// formats.md names, its description (so that other tools can read the file; rotacal's own
// built-ins are recognised from it).
std::string machine_lines(MachineType m);

// Rotary column names in chain order and the two angles of a sample in that order.
std::string rotary_header(MachineType m);
std::string rotary_values(MachineType m, double tilt_deg, double rot_deg);

std::string vec_text(const Eigen::Vector3d& v);

void check_label(const std::string& label, const char* what);

template <typename Sample, typename RowFn>
std::string with_annotations(const std::vector<Sample>& samples,
                             const std::vector<Annotation>& annotations, RowFn row) {
  std::string out;
  std::size_t a = 0;
  for (std::size_t i = 0; i <= samples.size(); ++i) {
    for (; a < annotations.size() && annotations[a].before_sample <= i; ++a)
      out += "# " + annotations[a].text + "\n";
    if (i < samples.size()) out += row(samples[i]);
  }
  return out;
}

// The writers refuse what the readers would refuse, so no file is written that cannot be
// read back (a simulation with absurd noise, a negative dwell).
void check_writable(double v, double lo, double hi, const char* what, std::size_t row);

template <typename Sample>
void check_samples(const std::vector<Sample>& samples) {
  double last = -kMaxAbsTimeS;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Sample& r = samples[i];
    check_writable(r.time, last, kMaxAbsTimeS, "time", i);
    last = r.time;
    for (int k = 0; k < 3; ++k)
      check_writable(r.xyz[k], -kMaxAbsPositionMm, kMaxAbsPositionMm, "X/Y/Z", i);
    check_writable(r.tilt_deg, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "tilt angle", i);
    check_writable(r.rot_deg, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "rotary angle", i);
  }
}

// One piece of an appending writer's text; throws IoError once the writer is closed.
void put(const std::unique_ptr<OutputStream>& f, const std::string& path, const std::string& text);
// A `# text` annotation line (newlines in the text become spaces).
std::string annotation_line(const std::string& text);
// Ends an appending writer's stream once: commits it (the file replaces the target) or
// discards it (the old file stays); nothing when it has ended already.
void end_stream(std::unique_ptr<OutputStream>& f, bool commit);

}  // namespace rotacal::io_detail
