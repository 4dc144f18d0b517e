// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The strict reading shared by the session-file formats (ballbar_session_file.cpp,
// rtest_session_file.cpp): bounded UTF-8 lines, metadata and header, fields with their columns,
// numbers within the limits of ballbar_file.hpp, errors naming file, line and column. The
// writing helpers the formats share are in session_text.hpp.
#include <charconv>
#include <cmath>
#include <fstream>
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "rotacal/io/ballbar_file.hpp"

namespace rotacal::io_detail {

inline constexpr const char* kBallbarFormat = "rotacal-ballbar/1";
inline constexpr const char* kRtestFormat = "rotacal-rtest/1";

std::string trim(const std::string& s);

// Shows at most ~80 characters of offending text in a message (an error message never
// echoes a megabyte line back).
std::string excerpt(const std::string& t);

// One field of a data row, with its 1-based character column for error messages.
struct Field {
  std::string text;
  int column = 1;
};

std::vector<Field> split_fields(const std::string& line);

// The parse state shared by both formats: file name, line number, metadata, header.
struct Reader {
  std::string name;
  int line_no = 0;
  Metadata metadata;
  std::vector<std::string> header;
  int header_line = 0;

  [[noreturn]] void fail(int line, int column, const std::string& what) const {
    throw ParseError(name, line, column, what);
  }

  double number(const Field& f, const std::string& what) const {
    double v = 0.0;
    const char* b = f.text.data();
    const char* e = b + f.text.size();
    const auto r = std::from_chars(b, e, v);
    if (f.text.empty()) fail(line_no, f.column, what + " is empty");
    if (r.ec != std::errc() || r.ptr != e)
      fail(line_no, f.column, what + ": '" + excerpt(f.text) + "' is not a number");
    if (!std::isfinite(v))
      fail(line_no, f.column, what + " is " + excerpt(f.text) + " (must be finite)");
    return v;
  }

  // A number within [lo, hi]: beyond, it cannot come from a machine tool.
  double bounded(const Field& f, const std::string& what, double lo, double hi,
                 const char* unit) const {
    const double v = number(f, what);
    if (v < lo || v > hi)
      fail(line_no, f.column,
           what + " " + excerpt(f.text) + " is outside [" + format_number(lo) + ", " +
               format_number(hi) + "] " + unit + " (wrong units, or not a measurement)");
    return v;
  }

  std::string label(const Field& f, const std::string& what) const {
    if (f.text.empty()) fail(line_no, f.column, what + " is empty");
    if (f.text.size() > kMaxLabelBytes)
      fail(line_no, f.column,
           what + " is longer than " + std::to_string(kMaxLabelBytes) + " bytes ('" +
               excerpt(f.text) + "')");
    return f.text;
  }

  const std::string* meta(const std::string& key) const {
    for (const auto& kv : metadata)
      if (kv.first == key) return &kv.second;
    return nullptr;
  }

  int meta_line(const std::string& key) const {
    for (std::size_t i = 0; i < metadata.size(); ++i)
      if (metadata[i].first == key) return meta_lines[i];
    return 0;
  }

  double meta_number(const std::string& key, const std::string& value, double lo = -1e300,
                     double hi = 1e300, const char* unit = "") const {
    Field f{trim(value), 0};
    Reader copy = *this;
    copy.line_no = meta_line(key);
    return copy.bounded(f, "metadata '" + key + "'", lo, hi, unit);
  }

  Eigen::Vector3d meta_vector(const std::string& key, const std::string& value,
                              double limit = 1e300, const char* unit = "") const {
    const std::vector<Field> parts = split_fields(value);
    if (parts.size() != 3)
      fail(meta_line(key), 0,
           "metadata '" + key + "' must be three numbers 'x, y, z', got '" + excerpt(value) + "'");
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k)
      v[k] = meta_number(key, parts[static_cast<std::size_t>(k)].text, -limit, limit, unit);
    return v;
  }

  std::vector<int> meta_lines;
};

// Reads metadata up to and including the column header; returns the rows that follow as
// (line number, text), with `#` lines after the header returned as annotations.
struct RawFile {
  std::vector<std::pair<int, std::string>> rows;
  std::vector<std::pair<std::size_t, std::string>> annotations;  // before row index
};

RawFile read_structure(std::istream& in, Reader& R, const char* expected_format);

int column_index(const Reader& R, const std::string& name, bool required);

// `# machine:` names a built-in, or `# machine_description:` (one line of rotacal-machine/1
// JSON) defines the machine, `# machine:` then being its free-text name (formats.md).
MachineType read_machine(const Reader& R);
void check_units(const Reader& R);
std::optional<double> read_noise(const Reader& R);

// Rotary columns must be named after the machine's axes: a column named after another rotary
// letter belongs to another machine.
void check_rotary_columns(const Reader& R, MachineType m);

std::vector<Field> row_fields(Reader& R, const std::pair<int, std::string>& row);

// Rows that repeat an earlier row exactly (same label, time and values: a recorder or a
// copy-paste wrote them twice). They are kept, as the file says, but reported: a fit would
// otherwise count one measurement twice and shrink its sigma by sqrt(2) without a word.
// Time never decreases in a valid file, so an exact repeat has the time of the rows just
// before it: only rows of the current time are kept (views into the RawFile's rows, which
// outlive this and are not modified), which keeps the check O(n) and cache-friendly.
struct DuplicateRows {
  std::unordered_map<std::string_view, int> first_line;
  double current_time = std::nan("");
  std::size_t count = 0;
  int example_line = 0, example_of = 0;

  void add(const std::pair<int, std::string>& row, int line, double time) {
    if (!(time == current_time)) {
      if (first_line.bucket_count() > 1024)
        first_line = {};  // one large group: do not clear it again and again
      first_line.clear();
      current_time = time;
    }
    const auto ins = first_line.emplace(std::string_view(row.second), line);
    if (!ins.second && count++ == 0) example_line = line, example_of = ins.first->second;
  }
  void report(std::vector<std::string>& warnings) const {
    if (count == 0) return;
    warnings.push_back(std::to_string(count) + " row" + (count > 1 ? "s repeat" : " repeats") +
                       " an earlier row exactly (first: line " + std::to_string(example_line) +
                       " repeats line " + std::to_string(example_of) +
                       "); each counts as a separate measurement in a fit: "
                       "remove them if they were written twice");
  }
};

void check_time(Reader& R, const Field& f, double t, double& last);
std::vector<Annotation> annotations_of(const RawFile& raw);
std::ifstream open_for_reading(const std::string& path);

// The first 4 kB of a file (`head`, bounded whatever the file) and its first non-blank line in
// them (`line`, untrimmed), with `in` rewound (opened again when it cannot seek): how the
// readers tell the formats apart (session_file.cpp).
struct FormatLine {
  std::string head;
  std::string line;
};
FormatLine sniff_format_line(std::ifstream& in, const std::string& path);
// read_session on a file already opened and sniffed (session_file.cpp).
AnySession read_sniffed_session(std::ifstream& in, const std::string& path,
                                const FormatLine& sniffed);

}  // namespace rotacal::io_detail
