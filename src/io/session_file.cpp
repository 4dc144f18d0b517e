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

namespace rotacal {

namespace {

const char* kBallbarFormat = "rotacal-ballbar/1";
const char* kRtestFormat = "rotacal-rtest/1";

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  const auto b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

// Shows at most ~80 characters of offending text in a message (an error message never
// echoes a megabyte line back).
std::string excerpt(const std::string& t) {
  if (t.size() <= 80) return t;
  std::size_t cut = 77;
  while (cut > 0 && (static_cast<unsigned char>(t[cut]) & 0xC0) == 0x80) --cut;  // whole UTF-8 chars
  return t.substr(0, cut) + "...";
}

// One field of a data row, with its 1-based character column for error messages.
struct Field {
  std::string text;
  int column = 1;
};

std::vector<Field> split_fields(const std::string& line) {
  std::vector<Field> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::string raw = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::size_t lead = raw.find_first_not_of(" \t");
    out.push_back({trim(raw), static_cast<int>(start + (lead == std::string::npos ? 0 : lead)) + 1});
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

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
    if (!std::isfinite(v)) fail(line_no, f.column, what + " is " + excerpt(f.text) + " (must be finite)");
    return v;
  }

  // A number within [lo, hi]: beyond, it cannot come from a machine tool.
  double bounded(const Field& f, const std::string& what, double lo, double hi, const char* unit) const {
    const double v = number(f, what);
    if (v < lo || v > hi)
      fail(line_no, f.column, what + " " + excerpt(f.text) + " is outside [" + format_number(lo) + ", " +
                                  format_number(hi) + "] " + unit + " (wrong units, or not a measurement)");
    return v;
  }

  std::string label(const Field& f, const std::string& what) const {
    if (f.text.empty()) fail(line_no, f.column, what + " is empty");
    if (f.text.size() > kMaxLabelBytes)
      fail(line_no, f.column, what + " is longer than " + std::to_string(kMaxLabelBytes) + " bytes ('" +
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

  Eigen::Vector3d meta_vector(const std::string& key, const std::string& value, double limit = 1e300,
                              const char* unit = "") const {
    const std::vector<Field> parts = split_fields(value);
    if (parts.size() != 3)
      fail(meta_line(key), 0, "metadata '" + key + "' must be three numbers 'x, y, z', got '" + excerpt(value) + "'");
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) v[k] = meta_number(key, parts[static_cast<std::size_t>(k)].text, -limit, limit, unit);
    return v;
  }

  std::vector<int> meta_lines;
};

// Length in bytes of the valid UTF-8 sequence at s[i], 0 if it is not one (RFC 3629: no
// overlong forms, no surrogates, at most U+10FFFF).
std::size_t utf8_length(const std::string& s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  if (c < 0x80) return 1;
  std::size_t n;
  unsigned cp;
  if (c >= 0xC2 && c <= 0xDF) n = 2, cp = c & 0x1F;
  else if (c >= 0xE0 && c <= 0xEF) n = 3, cp = c & 0x0F;
  else if (c >= 0xF0 && c <= 0xF4) n = 4, cp = c & 0x07;
  else return 0;
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(i + k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b(i + k) & 0x3F);
  }
  if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF)) || (cp >= 0xD800 && cp <= 0xDFFF))
    return 0;
  return n;
}

// Lines of a session file, read in bounded chunks: a line longer than kMaxLineBytes (a binary
// file, /dev/zero, a file with CR-only line ends) is refused as soon as it is seen, so memory
// stays bounded whatever the input. Each line is checked: UTF-8, no control characters but
// tab, a CR only as the CRLF line end.
class LineSource {
 public:
  LineSource(std::istream& in, const std::string& name) : in_(in), name_(name) {}

  bool next(std::string& line, int& line_no) {
    line.clear();
    for (;;) {
      if (pos_ == len_) {
        if (eof_) break;
        in_.read(buf_, sizeof buf_);
        len_ = static_cast<std::size_t>(in_.gcount());
        pos_ = 0;
        if (len_ == 0) {
          if (in_.bad()) throw IoError(name_ + ": read failed");
          eof_ = true;
          break;
        }
      }
      const char* start = buf_ + pos_;
      const void* nl = std::memchr(start, '\n', len_ - pos_);
      const std::size_t take = nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - start) : len_ - pos_;
      if (line.size() + take > kMaxLineBytes) too_long(line.append(start, std::min(take, std::size_t(100))));
      line.append(start, take);
      pos_ += take;
      if (nl) {
        ++pos_;
        return finish(line, line_no);
      }
    }
    if (line.empty()) return false;  // end of file
    return finish(line, line_no);
  }

 private:
  bool finish(std::string& line, int& line_no) {
    ++line_no_;
    line_no = line_no_;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // CRLF
    if (line_no_ == 1 && line.compare(0, 3, "\xEF\xBB\xBF") == 0)
      throw ParseError(name_, 1, 1, "the file starts with a UTF-8 byte-order mark (bytes EF BB BF); "
                                    "session files are UTF-8 without one: save it without the BOM");
    // Fast path: plain printable ASCII needs no further look.
    bool plain = true;
    for (const char ch : line) {
      const unsigned char c = static_cast<unsigned char>(ch);
      if (c < 0x20 || c >= 0x7F) {
        plain = false;
        break;
      }
    }
    if (plain) return true;
    for (std::size_t i = 0; i < line.size();) {
      const unsigned char c = static_cast<unsigned char>(line[i]);
      if (c == '\r')
        throw ParseError(name_, line_no_, static_cast<int>(i) + 1,
                         "carriage return inside a line (line ends must be LF or CRLF, not CR alone)");
      if (c < 0x20 && c != '\t') {
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02X", c);
        throw ParseError(name_, line_no_, static_cast<int>(i) + 1,
                         std::string("control character ") + hex + " (not a text file?)");
      }
      const std::size_t n = utf8_length(line, i);
      if (n == 0) {
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02X", c);
        throw ParseError(name_, line_no_, static_cast<int>(i) + 1,
                         std::string("byte ") + hex + " is not UTF-8 (session files are UTF-8 text)");
      }
      i += n;
    }
    return true;
  }

  [[noreturn]] void too_long(const std::string& head) const {
    std::string shown;
    for (char c : head.substr(0, 40)) shown += (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7F) ? '?' : c;
    throw ParseError(name_, line_no_ + 1, 0, "line longer than " + std::to_string(kMaxLineBytes) +
                                                 " bytes (a binary file, or CR-only line ends?), starting '" + shown + "...'");
  }

  std::istream& in_;
  std::string name_;
  char buf_[1 << 16];
  std::size_t pos_ = 0, len_ = 0;
  bool eof_ = false;
  int line_no_ = 0;
};

// Reads metadata up to and including the column header; returns the rows that follow as
// (line number, text), with `#` lines after the header returned as annotations.
struct RawFile {
  std::vector<std::pair<int, std::string>> rows;
  std::vector<std::pair<std::size_t, std::string>> annotations;  // before row index
};

RawFile read_structure(std::istream& in, Reader& R, const char* expected_format) {
  RawFile out;
  std::string line;
  bool format_seen = false;
  bool any = false;
  LineSource lines(in, R.name);
  while (lines.next(line, R.line_no)) {
    const std::string t = trim(line);
    if (t.empty()) continue;
    any = true;
    if (t[0] == '#') {
      const std::string body = trim(t.substr(1));
      if (!R.header.empty()) {
        out.annotations.emplace_back(out.rows.size(), body);
        continue;
      }
      const auto colon = body.find(':');
      if (colon == std::string::npos) {
        if (!format_seen) R.fail(R.line_no, 1, std::string("first line must be '# format: ") + expected_format + "'");
        out.annotations.emplace_back(0, body);  // a comment before the header: kept
        continue;
      }
      const std::string key = trim(body.substr(0, colon));
      const std::string value = trim(body.substr(colon + 1));
      if (!format_seen) {
        if (key != "format")
          R.fail(R.line_no, 1, std::string("first line must be '# format: ") + expected_format + "', got '" + excerpt(t) + "'");
        if (value != expected_format)
          R.fail(R.line_no, static_cast<int>(line.find(value)) + 1,
                 "format '" + excerpt(value) + "' is not " + expected_format);
        format_seen = true;
      }
      for (const auto& kv : R.metadata)
        if (kv.first == key) R.fail(R.line_no, 1, "metadata key '" + excerpt(key) + "' appears twice");
      R.metadata.emplace_back(key, value);
      R.meta_lines.push_back(R.line_no);
      continue;
    }
    if (!format_seen)
      R.fail(R.line_no, 1, std::string("first line must be '# format: ") + expected_format + "'");
    if (R.header.empty()) {
      for (const Field& f : split_fields(line)) {
        if (f.text.empty()) R.fail(R.line_no, f.column, "empty column name in the header");
        if (f.text.size() > kMaxLabelBytes)
          R.fail(R.line_no, f.column, "column name longer than " + std::to_string(kMaxLabelBytes) + " bytes");
        if (std::find(R.header.begin(), R.header.end(), f.text) != R.header.end())
          R.fail(R.line_no, f.column, "column '" + excerpt(f.text) + "' appears twice");
        R.header.push_back(f.text);
      }
      R.header_line = R.line_no;
      continue;
    }
    out.rows.emplace_back(R.line_no, line);
  }
  if (!any) R.fail(0, 0, "empty file");
  if (R.header.empty()) R.fail(R.line_no, 0, "no column header line");
  if (out.rows.empty()) R.fail(R.line_no, 0, "no data rows after the header");
  return out;
}

int column_index(const Reader& R, const std::string& name, bool required) {
  const auto it = std::find(R.header.begin(), R.header.end(), name);
  if (it == R.header.end()) {
    if (required) R.fail(R.header_line, 0, "missing required column '" + name + "'");
    return -1;
  }
  return static_cast<int>(it - R.header.begin());
}

// `# machine:` names a built-in, or `# machine_description:` (one line of rotacal-machine/1
// JSON) defines the machine, `# machine:` then being its free-text name (formats.md).
MachineType read_machine(const Reader& R) {
  const std::string* m = R.meta("machine");
  if (const std::string* d = R.meta("machine_description")) {
    const std::string where = R.name + ":" + std::to_string(R.meta_line("machine_description")) +
                              ": machine_description";
    try {
      return MachineType::from_description(parse_machine_description(*d, where));
    } catch (const InvalidArgument& e) {
      R.fail(R.meta_line("machine_description"), 0, e.what());
    }
  }
  if (!m) R.fail(0, 0, "missing metadata 'machine' (a built-in name such as AC-trt, or a machine_description)");
  try {
    return parse_machine_type(*m);
  } catch (const InvalidArgument&) {
    std::string known;
    for (const std::string& n : builtin_machine_names()) known += (known.empty() ? "" : ", ") + n;
    R.fail(R.meta_line("machine"), 0, "unknown machine '" + excerpt(*m) + "' (built-in: " + known +
                                          "; any other needs a '# machine_description:' line)");
  }
}

void check_units(const Reader& R) {
  const std::string* u = R.meta("units");
  if (!u) return;
  std::string compact;
  for (char c : *u)
    if (c != ' ') compact += c;
  if (compact != "mm,deg,s")
    R.fail(R.meta_line("units"), 0, "units '" + excerpt(*u) + "' are not supported (must be 'mm, deg, s')");
}

std::optional<double> read_noise(const Reader& R) {
  const std::string* n = R.meta("noise_um");
  if (!n) return std::nullopt;
  const double v = R.meta_number("noise_um", *n, 0.0, kMaxNoiseUm, "um");
  if (!(v > 0.0)) R.fail(R.meta_line("noise_um"), 0, "noise_um must be > 0, got " + excerpt(*n));
  return v;
}

// Rotary columns must be named after the machine's axes: a column named after another rotary
// letter belongs to another machine.
void check_rotary_columns(const Reader& R, MachineType m) {
  const std::string mine{m.description().axis(0).name, m.description().axis(1).name};
  for (const char* other : {"A", "B", "C"})
    if (mine.find(other[0]) == std::string::npos &&
        std::find(R.header.begin(), R.header.end(), other) != R.header.end())
      R.fail(R.header_line, 0, std::string("column '") + other + "' does not belong to a " + to_string(m) +
                                   " machine (rotary columns are " + mine.substr(0, 1) + ", " + mine.substr(1) + ")");
}

// The machine lines of a header: the name, and for every machine but the two tables that
// formats.md names, its description (so that other tools can read the file; rotacal's own
// built-ins are recognised from it).
std::string machine_lines(MachineType m) {
  std::string out = "# machine: " + to_string(m) + "\n";
  if (m != MachineType::AC_trt && m != MachineType::BC_trt)
    out += "# machine_description: " + machine_description_json(m.description()) + "\n";
  return out;
}

// Rotary column names in chain order and the two angles of a sample in that order.
std::string rotary_header(MachineType m) {
  return std::string(1, m.description().axis(0).name) + "," + m.description().axis(1).name;
}
std::string rotary_values(MachineType m, double tilt_deg, double rot_deg) {
  const bool rot_first = m.rot_index() == 0;
  return format_number(rot_first ? rot_deg : tilt_deg) + "," + format_number(rot_first ? tilt_deg : rot_deg);
}

std::vector<Field> row_fields(Reader& R, const std::pair<int, std::string>& row) {
  R.line_no = row.first;
  std::vector<Field> f = split_fields(row.second);
  if (f.size() != R.header.size())
    R.fail(row.first, 0, "expected " + std::to_string(R.header.size()) + " fields as in the header, got " +
                             std::to_string(f.size()));
  return f;
}

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
      if (first_line.bucket_count() > 1024) first_line = {};  // one large group: do not clear it again and again
      first_line.clear();
      current_time = time;
    }
    const auto ins = first_line.emplace(std::string_view(row.second), line);
    if (!ins.second && count++ == 0) example_line = line, example_of = ins.first->second;
  }
  void report(std::vector<std::string>& warnings) const {
    if (count == 0) return;
    warnings.push_back(std::to_string(count) + " row" + (count > 1 ? "s repeat" : " repeats") +
                       " an earlier row exactly (first: line " + std::to_string(example_line) + " repeats line " +
                       std::to_string(example_of) + "); each counts as a separate measurement in a fit: "
                       "remove them if they were written twice");
  }
};

void check_time(Reader& R, const Field& f, double t, double& last) {
  if (t < last)
    R.fail(R.line_no, f.column, "time " + excerpt(f.text) + " is before the previous row's (time must not decrease)");
  last = t;
}

std::vector<Annotation> annotations_of(const RawFile& raw) {
  std::vector<Annotation> out;
  for (const auto& a : raw.annotations) out.push_back({a.first, a.second});
  return out;
}

std::ifstream open_for_reading(const std::string& path) {
  if (path.find('\0') != std::string::npos)
    throw IoError(std::string(path.c_str()) + "...: path contains a NUL byte");
  if (path.empty()) throw IoError("(empty path): an input path must not be empty");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw IoError(path + ": is a directory, not a session file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open for reading: " + std::strerror(errno));
  return in;
}

std::string vec_text(const Eigen::Vector3d& v) {
  return format_number(v.x()) + ", " + format_number(v.y()) + ", " + format_number(v.z());
}

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

void check_label(const std::string& label, const char* what) {
  if (label.empty() || label.find_first_of(",\n\r#") != std::string::npos || trim(label) != label)
    throw InvalidArgument(std::string(what) + " '" + label +
                          "' cannot be written (empty, or contains a comma, '#', newline or edge spaces)");
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

// The writers refuse what the readers would refuse, so no file is written that cannot be
// read back (a simulation with absurd noise, a negative dwell).
void check_writable(double v, double lo, double hi, const char* what, std::size_t row) {
  if (!(v >= lo && v <= hi))
    throw InvalidArgument(std::string(what) + " " + (std::isfinite(v) ? format_number(v) : std::string("non-finite")) +
                          " of sample " + std::to_string(row) + " is outside [" + format_number(lo) + ", " +
                          format_number(hi) + "]: a file with it could not be read back");
}

template <typename Sample>
void check_samples(const std::vector<Sample>& samples) {
  double last = -kMaxAbsTimeS;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Sample& r = samples[i];
    check_writable(r.time, last, kMaxAbsTimeS, "time", i);
    last = r.time;
    for (int k = 0; k < 3; ++k) check_writable(r.xyz[k], -kMaxAbsPositionMm, kMaxAbsPositionMm, "X/Y/Z", i);
    check_writable(r.tilt_deg, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "tilt angle", i);
    check_writable(r.rot_deg, -kMaxAbsAngleDeg, kMaxAbsAngleDeg, "rotary angle", i);
  }
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
  // Sniff the format line from the first 4 kB only (a file without line ends stays bounded).
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  std::string line;
  for (std::size_t a = 0; a < head.size();) {
    const std::size_t nl = std::min(head.find('\n', a), head.size());
    line = head.substr(a, nl - a);
    if (!trim(line).empty()) break;
    a = nl + 1;
  }
  const std::string t = trim(line);
  in.clear();
  in.seekg(0);
  if (!in) {
    in = open_for_reading(path);  // not seekable: open again
  }
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
