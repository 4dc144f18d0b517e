// SPDX-License-Identifier: BSD-3-Clause
// The strict reading shared by the session-file formats (strict_reader.hpp).
#include "strict_reader.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace rotacal::io_detail {

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
  while (cut > 0 && (static_cast<unsigned char>(t[cut]) & 0xC0) == 0x80)
    --cut;  // whole UTF-8 chars
  return t.substr(0, cut) + "...";
}

std::vector<Field> split_fields(const std::string& line) {
  std::vector<Field> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::string raw =
        line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const std::size_t lead = raw.find_first_not_of(" \t");
    out.push_back(
        {trim(raw), static_cast<int>(start + (lead == std::string::npos ? 0 : lead)) + 1});
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

namespace {

// Length in bytes of the valid UTF-8 sequence at s[i], 0 if it is not one (RFC 3629: no
// overlong forms, no surrogates, at most U+10FFFF).
std::size_t utf8_length(const std::string& s, std::size_t i) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  if (c < 0x80) return 1;
  std::size_t n;
  unsigned cp;
  if (c >= 0xC2 && c <= 0xDF)
    n = 2, cp = c & 0x1F;
  else if (c >= 0xE0 && c <= 0xEF)
    n = 3, cp = c & 0x0F;
  else if (c >= 0xF0 && c <= 0xF4)
    n = 4, cp = c & 0x07;
  else
    return 0;
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((b(i + k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b(i + k) & 0x3F);
  }
  if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF)) ||
      (cp >= 0xD800 && cp <= 0xDFFF))
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
      const std::size_t take =
          nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - start) : len_ - pos_;
      if (line.size() + take > kMaxLineBytes)
        too_long(line.append(start, std::min(take, std::size_t(100))));
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
      throw ParseError(name_, 1, 1,
                       "the file starts with a UTF-8 byte-order mark (bytes EF BB BF); "
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
        throw ParseError(
            name_, line_no_, static_cast<int>(i) + 1,
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
        throw ParseError(
            name_, line_no_, static_cast<int>(i) + 1,
            std::string("byte ") + hex + " is not UTF-8 (session files are UTF-8 text)");
      }
      i += n;
    }
    return true;
  }

  [[noreturn]] void too_long(const std::string& head) const {
    std::string shown;
    for (char c : head.substr(0, 40))
      shown +=
          (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7F) ? '?' : c;
    throw ParseError(name_, line_no_ + 1, 0,
                     "line longer than " + std::to_string(kMaxLineBytes) +
                         " bytes (a binary file, or CR-only line ends?), starting '" + shown +
                         "...'");
  }

  std::istream& in_;
  std::string name_;
  char buf_[1 << 16];
  std::size_t pos_ = 0, len_ = 0;
  bool eof_ = false;
  int line_no_ = 0;
};

}  // namespace

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
        if (!format_seen)
          R.fail(R.line_no, 1,
                 std::string("first line must be '# format: ") + expected_format + "'");
        out.annotations.emplace_back(0, body);  // a comment before the header: kept
        continue;
      }
      const std::string key = trim(body.substr(0, colon));
      const std::string value = trim(body.substr(colon + 1));
      if (!format_seen) {
        if (key != "format")
          R.fail(R.line_no, 1,
                 std::string("first line must be '# format: ") + expected_format + "', got '" +
                     excerpt(t) + "'");
        if (value != expected_format)
          R.fail(R.line_no, static_cast<int>(line.find(value)) + 1,
                 "format '" + excerpt(value) + "' is not " + expected_format);
        format_seen = true;
      }
      for (const auto& kv : R.metadata)
        if (kv.first == key)
          R.fail(R.line_no, 1, "metadata key '" + excerpt(key) + "' appears twice");
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
          R.fail(R.line_no, f.column,
                 "column name longer than " + std::to_string(kMaxLabelBytes) + " bytes");
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
    const std::string where =
        R.name + ":" + std::to_string(R.meta_line("machine_description")) + ": machine_description";
    try {
      return MachineType::from_description(parse_machine_description(*d, where));
    } catch (const InvalidArgument& e) {
      R.fail(R.meta_line("machine_description"), 0, e.what());
    }
  }
  if (!m)
    R.fail(0, 0,
           "missing metadata 'machine' (a built-in name such as AC-trt, or a machine_description)");
  try {
    return parse_machine_type(*m);
  } catch (const InvalidArgument&) {
    std::string known;
    for (const std::string& n : builtin_machine_names()) known += (known.empty() ? "" : ", ") + n;
    R.fail(R.meta_line("machine"), 0,
           "unknown machine '" + excerpt(*m) + "' (built-in: " + known +
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
    R.fail(R.meta_line("units"), 0,
           "units '" + excerpt(*u) + "' are not supported (must be 'mm, deg, s')");
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
      R.fail(R.header_line, 0,
             std::string("column '") + other + "' does not belong to a " + to_string(m) +
                 " machine (rotary columns are " + mine.substr(0, 1) + ", " + mine.substr(1) + ")");
}

std::vector<Field> row_fields(Reader& R, const std::pair<int, std::string>& row) {
  R.line_no = row.first;
  std::vector<Field> f = split_fields(row.second);
  if (f.size() != R.header.size())
    R.fail(row.first, 0,
           "expected " + std::to_string(R.header.size()) + " fields as in the header, got " +
               std::to_string(f.size()));
  return f;
}

void check_time(Reader& R, const Field& f, double t, double& last) {
  if (t < last)
    R.fail(R.line_no, f.column,
           "time " + excerpt(f.text) + " is before the previous row's (time must not decrease)");
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
  struct stat st{};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw IoError(path + ": is a directory, not a session file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open for reading: " + std::strerror(errno));
  return in;
}

}  // namespace rotacal::io_detail
