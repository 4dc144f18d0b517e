// SPDX-License-Identifier: BSD-3-Clause
// FANUC pitch error compensation data (parameters 3620-3625 and the values by data number) of
// each table axis' positioning error (angle_map.hpp).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/io/compensation_table.hpp"
#include "rotacal/io/controller_export.hpp"
#include "shared.hpp"
#include "table_shared.hpp"

namespace rotacal {

namespace fanuc_table_detail {

using namespace table_detail;

// The compensation points k * interval, k = first..last, and the trims there relative to the
// reference position's (k = 0), in units of the detection unit times the magnification.
struct Grid {
  bool turn = false;  // an endless axis: one turn, k = 0..n
  int first = 0, last = 0;
  double interval_deg = 0.0;
  std::vector<double> trim_deg;  // at k = first..last
  double trim_at_reference_deg = 0.0;
};

Grid grid_of(const AxisErrorFunction& f, const RotaryAxis& ax, const CompensationTableOptions& o) {
  const std::string letter(1, f.axis);
  Grid g;
  g.interval_deg = o.spacing_deg;
  const double units = g.interval_deg / o.fanuc.detection_unit_deg;
  if (!(o.fanuc.detection_unit_deg > 0.0) || std::abs(units - std::round(units)) > 1e-6 ||
      units < 1.0)
    throw InvalidArgument("--spacing " + export_detail::fixed(g.interval_deg, 6) +
                          " deg: FANUC's interval (parameter 3624) is a whole number of detection "
                          "units (--fanuc-unit " +
                          export_detail::fixed(o.fanuc.detection_unit_deg, 6) + " deg)");
  g.turn = !ax.limits_deg && !o.range_deg.count(f.axis);
  if (g.turn) {
    const double n = 360.0 / g.interval_deg;
    if (std::abs(n - std::round(n)) > 1e-9)
      throw InvalidArgument("--spacing " + export_detail::fixed(g.interval_deg, 6) +
                            " deg: a FANUC turn table needs an interval that divides 360 deg");
    g.last = static_cast<int>(std::round(n));
  } else {
    const auto [lo, hi] = range_of(ax, o);
    g.first = std::min(0, static_cast<int>(std::floor(lo / g.interval_deg + 1e-9)));
    g.last = std::max(0, static_cast<int>(std::ceil(hi / g.interval_deg - 1e-9)));
  }
  g.trim_at_reference_deg = trim_deg(f, 0.0);
  for (int k = g.first; k <= g.last; ++k)
    g.trim_deg.push_back(trim_deg(f, k * g.interval_deg) - g.trim_at_reference_deg);
  if (g.turn && std::abs(g.trim_deg.back()) > 1e-9)
    throw InvalidArgument(
        "--tables fanuc: the values of a turn must sum to zero (parameter "
        "manual, 3625), and the model's " +
        letter + " positioning changes by " + export_detail::fixed(g.trim_deg.back(), 9) +
        " deg over a turn");
  return g;
}

// Whole units at the points (rounded absolutes, so rounding never accumulates; a turn ends at
// 0 exactly) and the values: the difference of each point's from the one before.
std::vector<long> values_of(const Grid& g, double unit_deg) {
  std::vector<long> q;
  for (const double t : g.trim_deg) q.push_back(std::lround(t / unit_deg));
  if (g.turn) q.back() = 0;
  std::vector<long> v;
  for (std::size_t i = 1; i < q.size(); ++i) v.push_back(q[i] - q[i - 1]);
  return v;
}

long largest(const std::vector<long>& v) {
  long m = 0;
  for (const long x : v) m = std::max(m, std::abs(x));
  return m;
}

int magnification_of(const Grid& g, const FanucPitchOptions& fo, const std::string& letter) {
  const int lo = fo.magnification ? fo.magnification : 1, hi = fo.magnification ? lo : 100;
  for (int m = lo; m <= hi; ++m)
    if (largest(values_of(g, fo.detection_unit_deg * m)) <= fo.max_value) return m;
  throw InvalidArgument(
      "--tables fanuc: a value of the " + letter + " table exceeds " +
      std::to_string(fo.max_value) + " (--fanuc-max-value, the series' range) at magnification " +
      (fo.magnification ? std::to_string(fo.magnification) : std::string("1..100")) +
      " (parameter 3623): use a smaller --spacing or a larger --fanuc-magnification");
}

// Worst |trim(x) - compensation(x)| inside the intervals: the compensation between two points
// lies between their values (output at the point or interpolated), so it is at most the
// farther of the two from the model, plus half a unit of rounding.
double worst_error_deg(const AxisErrorFunction& f, const Grid& g, double unit_deg, int samples) {
  double worst = 0.0;
  for (int k = g.first; k < g.last; ++k)
    for (int s = 0; s <= samples + 1; ++s) {
      const double x = (k + s / (samples + 1.0)) * g.interval_deg;
      const double t = trim_deg(f, x) - g.trim_at_reference_deg;
      const double a = g.trim_deg[static_cast<std::size_t>(k - g.first)];
      const double b = g.trim_deg[static_cast<std::size_t>(k - g.first + 1)];
      worst = std::max(worst, std::max(std::abs(t - a), std::abs(t - b)));
    }
  return worst + 0.5 * unit_deg;
}

CompensationTable one_table(const AxisErrorFunction& f, const MachineType& m,
                            const CompensationTableOptions& o, const ExportInput& in,
                            int& next_number) {
  const RotaryAxis& ax = m.description().axis(f.chain_index);
  const std::string letter(1, f.axis);
  const Grid g = grid_of(f, ax, o);
  const FanucPitchOptions& fo = o.fanuc;
  const int mag = magnification_of(g, fo, letter);
  const double unit = fo.detection_unit_deg * mag;
  const std::vector<long> v = values_of(g, unit);
  // Data numbers: a turn from the reference number R (it holds the last value again); a range
  // from its most negative section, R - first + ... so that R + k is the section ending at k.
  const int lowest = next_number, reference = g.turn ? lowest : lowest - (g.first + 1);
  const int highest = reference + g.last;
  if (highest > fo.last_number)
    throw InvalidArgument("--tables fanuc: the " + letter + " table needs data numbers " +
                          std::to_string(lowest) + ".." + std::to_string(highest) +
                          ", past the control's last, " + std::to_string(fo.last_number) +
                          " (--fanuc-last-number): use a larger --spacing");
  next_number = highest + 1;
  CompensationTable t;
  t.axis = f.axis;
  t.joint = -1;
  t.holds = positioning_sources(f, ax);
  t.file_name = "pitch_" + letter + ".txt";
  for (int k = g.first; k <= g.last; ++k) t.nominal_deg.push_back(k * g.interval_deg);
  t.max_interpolation_error_deg = worst_error_deg(f, g, unit, o.samples_between);
  const double err = t.max_interpolation_error_deg;
  export_detail::Writer w(CommentDialect::fanuc);
  w.line("rotacal export: FANUC pitch error compensation of axis " + letter +
         ": enter the parameters and the values by data number");
  w.line("holds: positioning_" + letter + " (actual - commanded angle) from " +
         joined(positioning_sources(f, ax), "no term of the model"));
  w.line(
      "sign: a value is the section's change of the compensation the control adds to the "
      "motor command (nominal - actual), in " +
      export_detail::fixed(unit, 6) + " deg units (detection unit " +
      export_detail::fixed(fo.detection_unit_deg, 6) + " deg x magnification " +
      std::to_string(mag) + ")");
  w.line("not in the table: the trim at the reference position, " +
         export_detail::fixed(g.trim_at_reference_deg, 6) +
         " deg: the compensation is zero at the reference position (0 deg), so this part is the "
         "axis' zero offset");
  w.line("worst error between points: " + rounded_up(err) + " deg (" +
         rounded_up(err / kRadToDeg * 1e6) +
         " urad), with the output at the points or "
         "interpolated, and the rounding");
  if (!g.turn)
    w.line("correction stops outside " + export_detail::fixed(g.first * g.interval_deg, 6) + ".." +
           export_detail::fixed(g.last * g.interval_deg, 6) + " deg");
  for (const std::string& n : f.notes) w.line("left out: " + n);
  w.line("model: " + (in.model_path.empty() ? std::string("(not named)") : in.model_path));
  w.line("written: " + (o.generated_at.empty() ? table_written_at() : o.generated_at));
  std::ostringstream out;
  out << w.out.str();
  const auto param = [&](int no, long value, const std::string& what) {
    out << "PARAMETER " << no << " " << letter << " = " << value << " (" << what << ")\n";
  };
  param(3620, reference, "reference position number");
  param(3621, g.turn ? reference : reference + g.first + 1, "most negative number");
  param(3622, highest, "most positive number");
  param(3623, mag, "magnification");
  param(3624, std::lround(g.interval_deg / fo.detection_unit_deg), "interval");
  param(3625, g.turn ? std::lround(360.0 / fo.detection_unit_deg) : 0, "travel per turn");
  if (g.turn) out << "DATA " << reference << " = " << v.back() << "\n";
  for (std::size_t i = 0; i < v.size(); ++i) {
    const int k = g.first + 1 + static_cast<int>(i);
    out << "DATA " << reference + k << " = " << v[i] << "\n";
    t.value_deg.push_back(static_cast<double>(v[i]) * unit);
  }
  t.text = out.str();
  t.summary = "axis " + letter + " positioning, data numbers " + std::to_string(lowest) + ".." +
              std::to_string(highest) + (g.turn ? " (one turn)" : "") + ", magnification " +
              std::to_string(mag) + ", worst error " + rounded_up(err / kRadToDeg * 1e6) + " urad";
  return t;
}

}  // namespace fanuc_table_detail

CompensationTables fanuc_pitch_tables(const ModelFile& model,
                                      const std::vector<AxisErrorFunction>& functions,
                                      const CompensationTableOptions& o) {
  int next_number = o.fanuc.first_number;  // the axes' tables take consecutive data numbers
  return table_detail::positioning_tables(
      model, functions, o, "FANUC", "FANUC's pitch error compensation",
      [&](const AxisErrorFunction& f, const MachineType& m, const CompensationTableOptions& opt,
          const ExportInput& in) {
        return fanuc_table_detail::one_table(f, m, opt, in, next_number);
      });
}

}  // namespace rotacal
