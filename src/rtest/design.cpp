// Test design: the R-test nests and pose grid with the smallest predicted uncertainty.
#include "rotacal/rtest/design.hpp"

#include <cmath>
#include <algorithm>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/rtest/model.hpp"

namespace rotacal {

namespace {

std::string fmt(double v, int digits = 1) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

// The whitener of AR(1) noise with coefficient rho and marginal sigma per stream (one per nest
// and component dx, dy, dz, in time order, as noise_gen::ar1 and the noise model split them):
//   w_0 = x_0 / sigma,   w_t = (x_t - rho x_{t-1}) / (sigma sqrt(1 - rho^2))   (Prais-Winsten).
// With it the joint fit's covariance is (J^T Sigma^-1 J)^-1, the GLS covariance under that
// noise, with no rescaling by the (zero) residual variance of noise-free readings. rho = 0
// gives W = I / sigma, i.e. (J^T J)^-1 sigma^2.
class Ar1Whitener : public ResidualWhitener {
 public:
  Ar1Whitener(const RtestSession& s, double sigma_mm, double rho) : n_(3 * static_cast<Eigen::Index>(s.samples.size())) {
    inv_first_ = 1.0 / sigma_mm;
    inv_next_ = 1.0 / (sigma_mm * std::sqrt(1.0 - rho * rho));
    rho_ = rho;
    std::map<std::string, std::vector<std::size_t>> by_nest;
    for (std::size_t i = 0; i < s.samples.size(); ++i) by_nest[s.samples[i].setup].push_back(i);
    for (auto& [nest, rows] : by_nest) {
      std::stable_sort(rows.begin(), rows.end(),
                       [&](std::size_t a, std::size_t b) { return s.samples[a].time < s.samples[b].time; });
      for (int k = 0; k < 3; ++k) {
        std::vector<Eigen::Index> stream;
        for (std::size_t i : rows) stream.push_back(3 * static_cast<Eigen::Index>(i) + k);
        streams_.push_back(std::move(stream));
      }
    }
  }
  void apply(Eigen::Ref<Eigen::MatrixXd> columns) const override {
    for (const auto& st : streams_) {
      for (std::size_t t = st.size(); t-- > 1;)
        columns.row(st[t]) = (columns.row(st[t]) - rho_ * columns.row(st[t - 1])) * inv_next_;
      columns.row(st[0]) *= inv_first_;
    }
  }
  Eigen::Index size() const override { return n_; }

 private:
  Eigen::Index n_;
  double inv_first_ = 1.0, inv_next_ = 1.0, rho_ = 0.0;
  std::vector<std::vector<Eigen::Index>> streams_;
};

// min, min + step, ..., up to max (the end added when off the grid).
std::vector<double> steps(double lo, double hi, double step) {
  std::vector<double> v;
  for (int k = 0; lo + k * step <= hi + 1e-9; ++k) v.push_back(lo + k * step);
  if (hi - v.back() > 1e-9) v.push_back(hi);
  return v;
}

}  // namespace

RtestDesignCandidate evaluate_rtest_design(const RtestPattern& pattern, const RtestDesignOptions& o,
                                           double budget) {
  RtestDesignCandidate c;
  c.pattern = pattern;
  const MachineType m = MachineType::BC_trt;
  const std::size_t poses = pattern.b_deg.size() * pattern.c_deg.size();
  c.duration_s = static_cast<double>(poses * pattern.nests.size()) * pattern.dwell_s;
  if (budget <= 0.0) budget = c.duration_s;
  if (c.duration_s > budget * (1 + 1e-12)) {
    c.why_not = fmt(c.duration_s, 0) + " s is over the time budget of " + fmt(budget, 0) + " s";
    return c;
  }
  const double deg = M_PI / 180.0;
  const char* axis = "XYZ";
  for (double b : pattern.b_deg)
    if (b < o.b_limits_deg[0] - 1e-9 || b > o.b_limits_deg[1] + 1e-9) {
      c.why_not = "B = " + fmt(b) + " deg is outside the B limits";
      return c;
    }
  for (std::size_t n = 0; n < pattern.nests.size(); ++n)
    for (double b : pattern.b_deg)
      for (double cc : pattern.c_deg) {
        const Eigen::Vector3d xyz = rtest_commanded_xyz(m, pattern.nests[n], {b * deg, cc * deg});
        for (int k = 0; k < 3; ++k)
          if (xyz[k] < o.travel_min[k] || xyz[k] > o.travel_max[k]) {
            c.why_not = std::string(1, axis[k]) + " = " + fmt(xyz[k], 3) + " mm for nest " + std::to_string(n + 1) +
                        " at B " + fmt(b) + ", C " + fmt(cc) + " deg is outside the travel " + fmt(o.travel_min[k]) +
                        ".." + fmt(o.travel_max[k]) + " mm";
            return c;
          }
      }
  // The R-test joint fit on the nominal machine's noise-free readings, whitened by sigma.
  RtestSimOptions sim;
  sim.pattern = pattern;
  sim.noise_um = 0.0;
  sim.probe_zero_um = 0.0;
  RtestSession s;
  try {
    s = simulate_rtest(MachineModel::nominal(m), sim).session;
  } catch (const InvalidArgument& e) {
    c.why_not = e.what();
    return c;
  }
  s.noise_um = o.noise_um;  // the fit's chi-square scale (observability), as a recorder declares it
  RtestJointOptions fit;
  fit.basis = o.basis;
  fit.whitener = std::make_shared<Ar1Whitener>(s, o.noise_um * 1e-3, o.noise_rho);
  RtestJointIdentification id;
  try {
    id = identify_joint(s, fit);
  } catch (const InvalidArgument& e) {
    c.why_not = e.what();
    return c;
  }
  // Information at the budget: the pattern repeated to fill it (the AR(1) correlation between
  // the end of one run and the start of the next is neglected).
  const double var_scale = c.duration_s / budget;
  const Eigen::Index p = static_cast<Eigen::Index>(id.parameters.size());
  c.sigma.resize(p);
  for (Eigen::Index j = 0; j < p; ++j) {
    const ParameterEstimate& e = id.parameters[static_cast<std::size_t>(j)];
    c.names.push_back(e.name);
    c.sigma[j] = e.observable ? std::sqrt(std::max(id.covariance(j, j), 0.0) * var_scale)
                              : std::numeric_limits<double>::infinity();
  }
  for (int i = 0; i < 8; ++i) {
    if (!std::isfinite(c.sigma[i])) {
      c.why_not = c.names[static_cast<std::size_t>(i)] + " is not determined by this pattern";
      return c;
    }
    const double u = 2.0 * c.sigma[i] * (location_error_is_angle(i) ? o.reference_radius_mm * 1e3 : 1e3);
    if (u > c.worst_expanded_um) c.worst_expanded_um = u, c.worst_error = c.names[static_cast<std::size_t>(i)];
  }
  // A pattern whose fit holds map coefficients fits a smaller model: its location errors
  // look better only because the maps are assumed zero. Such a pattern is not comparable.
  for (Eigen::Index j = 8; j < p; ++j)
    if (!std::isfinite(c.sigma[j])) {
      c.why_not = c.names[static_cast<std::size_t>(j)] +
                  " is not determined: the pose grid is too coarse for the joint fit's basis";
      return c;
    }
  c.feasible = true;
  return c;
}

RtestDesign design_rtest_test(const RtestDesignOptions& o) {
  if (o.nest_radius_mm.empty() || o.nest_height_mm.empty() || o.b_step_deg.empty() || o.c_step_deg.empty())
    throw InvalidArgument("design rtest: --radii, --heights, --b-steps and --c-steps need at least one value each");
  for (double v : o.b_step_deg)
    if (!(v > 0.0)) throw InvalidArgument("design rtest: --b-steps must be > 0 deg");
  for (double v : o.c_step_deg)
    if (!(v > 0.0 && v < 360.0)) throw InvalidArgument("design rtest: --c-steps must be in (0, 360) deg");
  for (double v : o.nest_radius_mm)
    if (!(v >= 0.0)) throw InvalidArgument("design rtest: --radii must be >= 0 mm");
  if (!(o.noise_um > 0.0)) throw InvalidArgument("design rtest: --noise must be > 0 um");
  if (!(o.noise_rho >= 0.0 && o.noise_rho <= 0.999)) throw InvalidArgument("design rtest: --rho must be in [0, 0.999]");
  if (!(o.reference_radius_mm > 0.0)) throw InvalidArgument("design rtest: the reference radius must be > 0 mm");
  if (!(o.base.dwell_s > 0.0)) throw InvalidArgument("design rtest: --dwell must be > 0 s");
  if (!(o.b_limits_deg[0] < o.b_limits_deg[1])) throw InvalidArgument("design rtest: --b-limits must be min < max deg");
  if (!(o.time_budget_s >= 0.0) || !std::isfinite(o.time_budget_s))
    throw InvalidArgument("design rtest: --time must be >= 0 s");
  RtestDesign out;
  out.baseline = evaluate_rtest_design(o.base, o, o.time_budget_s);
  out.time_budget_s = o.time_budget_s > 0.0 ? o.time_budget_s : out.baseline.duration_s;
  std::string reasons;
  const auto consider = [&](const RtestPattern& p) {
    RtestDesignCandidate c = evaluate_rtest_design(p, o, out.time_budget_s);
    if (c.feasible && (!out.best.feasible || c.worst_expanded_um < out.best.worst_expanded_um)) out.best = c;
    if (!c.feasible && reasons.size() < 400) reasons += "; " + c.why_not;
    out.candidates.push_back(std::move(c));
  };
  // Nests at the base grid, then the grid at the best nests.
  for (double r1 : o.nest_radius_mm)
    for (double h1 : o.nest_height_mm)
      for (double r2 : o.nest_radius_mm)
        for (double h2 : o.nest_height_mm) {
          RtestPattern p = o.base;
          p.nests = {Eigen::Vector3d(r1, 0.0, h1), Eigen::Vector3d(0.0, -r2, h2)};
          consider(p);
        }
  if (!out.best.feasible) throw InvalidArgument("design rtest: no nest pair is feasible" + reasons);
  const std::vector<Eigen::Vector3d> nests = out.best.pattern.nests;
  for (double bs : o.b_step_deg)
    for (double cs : o.c_step_deg) {
      RtestPattern p = o.base;
      p.nests = nests;
      p.b_deg = steps(o.b_limits_deg[0], o.b_limits_deg[1], bs);
      p.c_deg = steps(0.0, 360.0 - cs, cs);
      consider(p);
    }
  if (out.baseline.feasible) out.ratio = out.best.worst_expanded_um / out.baseline.worst_expanded_um;
  return out;
}

}  // namespace rotacal
