// SPDX-License-Identifier: BSD-3-Clause
// The epoch column and duty lines of a thermal session (formats.md "Thermal test").
#include "rotacal/io/thermal_file.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "strict_reader.hpp"

namespace rotacal {

using namespace io_detail;

namespace {

// "duty.N" -> N; 0 for a key that is not "duty."-anything (other metadata, kept as it is); -1
// for "duty." followed by anything but a positive integer without leading zeros (< 1e6).
int duty_number(const std::string& key) {
  if (!is_duty_key(key)) return 0;
  const std::string digits = key.substr(5);
  if (digits.empty() || digits.size() > 6 || digits[0] == '0') return -1;
  int n = 0;
  for (char c : digits) {
    if (c < '0' || c > '9') return -1;
    n = 10 * n + (c - '0');
  }
  return n;
}

DutyEntry parse_duty(const Reader& R, const std::string& key, const std::string& value,
                     MachineType m) {
  const int line = R.meta_line(key);
  const std::vector<Field> parts = split_fields(value);
  Reader at = R;
  at.line_no = line;
  DutyEntry d;
  d.time = at.bounded(Field{trim(parts[0].text), 0}, key + " TIME", 0.0, kMaxAbsTimeS, "s");
  if (parts.size() < 2) at.fail(line, 0, key + " names no axis ('TIME, AXIS=SPEED, ...')");
  const char axes[2] = {tilt_axis_letter(m), rot_axis_letter(m)};
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const std::string f = trim(parts[i].text);
    const std::size_t eq = f.find('=');
    if (eq == std::string::npos)
      at.fail(line, 0, key + ": '" + excerpt(f) + "' is not AXIS=SPEED (rev/min)");
    const std::string name = trim(f.substr(0, eq));
    if (name.size() != 1 || (name[0] != axes[0] && name[0] != axes[1]))
      at.fail(line, 0,
              key + " names axis '" + excerpt(name) + "', which machine " + to_string(m) +
                  " lacks (its rotary axes: " + std::string(1, axes[0]) + ", " +
                  std::string(1, axes[1]) + ")");
    for (const auto& s : d.speed)
      if (s.first == name[0]) at.fail(line, 0, key + " names axis " + name + " twice");
    const double v = at.bounded(Field{trim(f.substr(eq + 1)), 0}, key + " speed of " + name,
                                -kMaxDutySpeedRpm, kMaxDutySpeedRpm, "rev/min");
    d.speed.emplace_back(name[0], v);
  }
  return d;
}

std::vector<DutyEntry> read_duty(const Reader& R, MachineType m) {
  int count = 0;
  for (const auto& kv : R.metadata) {
    const int n = duty_number(kv.first);
    if (n < 0)
      R.fail(R.meta_line(kv.first), 0,
             "'" + excerpt(kv.first) + "' is not a duty.N entry (N = 1, 2, ...)");
    if (n > 0) ++count;
  }
  std::vector<DutyEntry> out;
  for (int n = 1; n <= count; ++n) {
    const std::string key = "duty." + std::to_string(n);
    const std::string* v = R.meta(key);
    if (!v)
      R.fail(0, 0, "duty entries must be numbered consecutively from 1: " + key + " is missing");
    out.push_back(parse_duty(R, key, *v, m));
    if (n > 1 && !(out.back().time > out[out.size() - 2].time))
      R.fail(R.meta_line(key), 0,
             key + " TIME " + format_number(out.back().time) + " s must be after duty." +
                 std::to_string(n - 1) + "'s " + format_number(out[out.size() - 2].time) + " s");
  }
  return out;
}

}  // namespace

bool is_thermal_session(const std::string& path) {
  std::ifstream in = open_for_reading(path);
  const FormatLine f = sniff_format_line(in, path);
  return f.head.find("# duty.") != std::string::npos ||
         f.head.find(",epoch\n") != std::string::npos ||
         f.head.find(",epoch\r\n") != std::string::npos;
}

ThermalSession read_thermal_session(const std::string& path) {
  ThermalSession out{read_instrument_session(path), {}, {}};
  MachineType m;
  const char* format = nullptr;
  std::size_t rows = 0;
  if (const auto* p = std::get_if<ProbeSession>(&out.session)) {
    m = p->machine, format = "rotacal-probe/1", rows = p->samples.size();
    out.warnings = p->warnings;
  } else if (const auto* r = std::get_if<RtestSession>(&out.session)) {
    m = r->machine, format = kRtestFormat, rows = r->samples.size();
    out.warnings = r->warnings;
  } else {
    throw InvalidArgument(path + ": a thermal test is a touch-probe or R-test session");
  }
  Reader R;
  R.name = path;
  out.warnings.erase(
      std::remove(out.warnings.begin(), out.warnings.end(), std::string(kThermalSessionPooled)),
      out.warnings.end());  // this reader fits the drift
  std::ifstream in = open_for_reading(path);
  const RawFile raw = read_structure(in, R, format);
  ThermalTest& th = out.thermal;
  th.duty = read_duty(R, m);
  const int c_epoch = column_index(R, "epoch", false);
  if (c_epoch < 0) {
    if (!th.duty.empty())
      R.fail(R.meta_line("duty.1"), 0,
             "duty lines need an 'epoch' column (formats.md, thermal test): which rows were "
             "measured while the axes were held");
    return out;
  }
  const int c_time = column_index(R, "time", true);
  ROTACAL_ASSERT(raw.rows.size() == rows);
  int last = 0;
  for (const auto& row : raw.rows) {
    const std::vector<Field> f = row_fields(R, row);
    const Field& e = f[static_cast<std::size_t>(c_epoch)];
    const double v = R.bounded(e, "epoch", 1.0, 1.0e9, "");
    if (v != std::floor(v))
      R.fail(R.line_no, e.column, "epoch " + excerpt(e.text) + " is not an integer");
    const int k = static_cast<int>(v);
    if (k < last)
      R.fail(R.line_no, e.column,
             "epoch " + std::to_string(k) + " after epoch " + std::to_string(last) +
                 ": epochs never decrease (the rows of one pause of the duty are together)");
    last = k;
    th.epoch.push_back(k);
    th.time.push_back(R.number(f[static_cast<std::size_t>(c_time)], "time"));
  }
  if (!th.duty.empty() && !th.time.empty() && th.duty.front().time < th.time.front())
    out.warnings.push_back("duty.1 starts at " + format_number(th.duty.front().time) +
                           " s, before the first row (" + format_number(th.time.front()) +
                           " s): the lag state starts at 0 at the first row");
  return out;
}

ThermalTest read_duty_file(const std::string& path, MachineType machine) {
  std::ifstream in = open_for_reading(path);
  if (sniff_format_line(in, path).line.rfind("# format:", 0) == 0) {  // a thermal session
    const ThermalSession s = read_thermal_session(path);
    const MachineType m = std::visit([](const auto& x) { return x.machine; }, s.session);
    if (!(m == machine))
      throw InvalidArgument(path + ": a session of machine " + to_string(m) + ", the model's is " +
                            to_string(machine));
    if (s.thermal.duty.empty())
      throw InvalidArgument(path + ": no '# duty.N:' lines: no duty to predict");
    return s.thermal;
  }
  Reader R;
  R.name = path;
  std::string line;
  while (std::getline(in, line)) {
    ++R.line_no;
    if (R.line_no > 100000) R.fail(R.line_no, 0, "more than 100000 lines: not a duty file");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string t = trim(line);
    if (t.empty()) continue;
    const std::size_t colon = t.find(':');
    if (t[0] != '#' || colon == std::string::npos)
      R.fail(R.line_no, 0,
             "'" + excerpt(t) + "' is not a '# duty.N: TIME, AXIS=SPEED, ...' line (formats.md)");
    const std::string key = trim(t.substr(1, colon - 1));
    for (const auto& kv : R.metadata)
      if (kv.first == key) R.fail(R.line_no, 0, "'" + excerpt(key) + "' given twice");
    R.metadata.emplace_back(key, trim(t.substr(colon + 1)));
    R.meta_lines.push_back(R.line_no);
  }
  ThermalTest th;
  th.duty = read_duty(R, machine);
  if (th.duty.empty()) throw InvalidArgument(path + ": no '# duty.N:' lines: no duty to predict");
  th.time = {0.0, th.duty.back().time + 1.0};  // from cold at 0 s; the last entry runs on
  return th;
}

}  // namespace rotacal
