// Test design: the R-test nests and pose grid with the smallest predicted uncertainty.
#include "rotacal/rtest/design.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "rotacal/core/error.hpp"
#include "rotacal/core/joint_fit.hpp"
#include "rotacal/core/least_squares.hpp"
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
  Ar1Whitener(const RtestSession& s, double sigma_mm, double rho)
      : n_(3 * static_cast<Eigen::Index>(s.samples.size())) {
    inv_first_ = 1.0 / sigma_mm;
    inv_next_ = 1.0 / (sigma_mm * std::sqrt(1.0 - rho * rho));
    rho_ = rho;
    std::map<std::string, std::vector<std::size_t>> by_nest;
    for (std::size_t i = 0; i < s.samples.size(); ++i) by_nest[s.samples[i].setup].push_back(i);
    for (auto& [nest, rows] : by_nest) {
      std::stable_sort(rows.begin(), rows.end(), [&](std::size_t a, std::size_t b) {
        return s.samples[a].time < s.samples[b].time;
      });
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

// BC-trt with the design's travel and B limits: the user's machine, which may be larger than
// the built-in description, whose travel would refuse the readings of a pattern the design
// allows (issue 32: --travel could not widen it).
MachineType design_machine(const RtestDesignOptions& o) {
  MachineDescription d = MachineType(MachineType::BC_trt).description();
  d.name = "BC-trt within the design's travel";
  Eigen::Matrix<double, 3, 2> travel;
  travel.col(0) = o.travel_min;
  travel.col(1) = o.travel_max;
  d.travel_mm = travel;
  for (RotaryAxis& a : d.table_axes)
    if (a.name == 'B') a.limits_deg = o.b_limits_deg;
  return MachineType::from_description(d);
}

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
            c.why_not = std::string(1, axis[k]) + " = " + fmt(xyz[k], 3) + " mm for nest " +
                        std::to_string(n + 1) + " at B " + fmt(b) + ", C " + fmt(cc) +
                        " deg is outside the travel " + fmt(o.travel_min[k]) + ".." +
                        fmt(o.travel_max[k]) + " mm";
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
    s = simulate_rtest(MachineModel::nominal(design_machine(o)), sim).session;
  } catch (const InvalidArgument& e) {
    c.why_not = e.what();
    return c;
  }
  s.machine = m;  // the same readings: the fit is of the BC-trt error model
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
    const double u =
        2.0 * c.sigma[i] * (location_error_is_angle(i) ? o.reference_radius_mm * 1e3 : 1e3);
    if (u > c.worst_expanded_um)
      c.worst_expanded_um = u, c.worst_error = c.names[static_cast<std::size_t>(i)];
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
  if (o.nest_radius_mm.empty() || o.nest_height_mm.empty() || o.b_step_deg.empty() ||
      o.c_step_deg.empty())
    throw InvalidArgument(
        "design rtest: --radii, --heights, --b-steps and --c-steps need at least one value each");
  for (double v : o.b_step_deg)
    if (!(v > 0.0)) throw InvalidArgument("design rtest: --b-steps must be > 0 deg");
  for (double v : o.c_step_deg)
    if (!(v > 0.0 && v < 360.0))
      throw InvalidArgument("design rtest: --c-steps must be in (0, 360) deg");
  for (double v : o.nest_radius_mm)
    if (!(v >= 0.0)) throw InvalidArgument("design rtest: --radii must be >= 0 mm");
  if (!(o.noise_um > 0.0)) throw InvalidArgument("design rtest: --noise must be > 0 um");
  if (!(o.noise_rho >= 0.0 && o.noise_rho <= 0.999))
    throw InvalidArgument("design rtest: --rho must be in [0, 0.999]");
  if (!(o.reference_radius_mm > 0.0))
    throw InvalidArgument("design rtest: the reference radius must be > 0 mm");
  if (!(o.base.dwell_s > 0.0)) throw InvalidArgument("design rtest: --dwell must be > 0 s");
  if (!(o.b_limits_deg[0] < o.b_limits_deg[1]))
    throw InvalidArgument("design rtest: --b-limits must be min < max deg");
  if (!(o.time_budget_s >= 0.0) || !std::isfinite(o.time_budget_s))
    throw InvalidArgument("design rtest: --time must be >= 0 s");
  RtestDesign out;
  out.baseline = evaluate_rtest_design(o.base, o, o.time_budget_s);
  out.time_budget_s = o.time_budget_s > 0.0 ? o.time_budget_s : out.baseline.duration_s;
  std::string reasons;
  const auto consider = [&](const RtestPattern& p) {
    RtestDesignCandidate c = evaluate_rtest_design(p, o, out.time_budget_s);
    if (c.feasible && (!out.best.feasible || c.worst_expanded_um < out.best.worst_expanded_um))
      out.best = c;
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
  if (out.baseline.feasible)
    out.ratio = out.best.worst_expanded_um / out.baseline.worst_expanded_um;
  return out;
}

}  // namespace rotacal

// ------------------------------------------------------------------ separating two effects

namespace rotacal {

namespace {

// R-test readings d = T(B, C, t)^-1 tool(xyz, t) - q_nest + zero_nest of several nests, 3 rows
// per pose. Parameters: 8 location errors, 3 probe-zero components per nest, then effects.
struct RtestPose {
  int nest = 0;
  Eigen::Vector3d q = Eigen::Vector3d::Zero(), xyz = Eigen::Vector3d::Zero();
  RotaryAngles<double> angles;
  double t = 0.0;
  Eigen::Vector3d d = Eigen::Vector3d::Zero();  ///< measured displacement (0 for a design)
};

class RtestReadingsModel : public ResidualModel {
 public:
  // fx by value: callers pass a model centred on the session (a temporary).
  RtestReadingsModel(std::vector<RtestPose> poses, int nests, EffectModel fx)
      : poses_(std::move(poses)), nests_(nests), fx_(std::move(fx)), P_(fx_.num_params()) {}
  Eigen::Index num_residuals() const override {
    return 3 * static_cast<Eigen::Index>(poses_.size());
  }
  int num_parameters() const override { return 8 + 3 * nests_ + P_; }
  Eigen::Index num_items() const override { return static_cast<Eigen::Index>(poses_.size()); }
  int rows_per_item() const override { return 3; }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    evaluate_with_jets([this](Eigen::Index i, const auto* p, auto* out) { sample(i, p, out); },
                       num_items(), 3, x, r, J);
  }

 private:
  template <typename T>
  void sample(Eigen::Index i, const T* p, T* out) const {
    const RtestPose& s = poses_[static_cast<std::size_t>(i)];
    const Vec3<T> d =
        rtest_reading<T>(MachineType::BC_trt, LocationErrors<T>::from_ptr(p), fx_,
                         P_ > 0 ? p + 8 + 3 * nests_ : nullptr, s.xyz, s.angles, s.t, s.q);
    for (int k = 0; k < 3; ++k) out[k] = d[k] + p[8 + 3 * s.nest + k] - T(s.d[k]);
  }
  std::vector<RtestPose> poses_;
  int nests_;
  EffectModel fx_;
  int P_;
};

Eigen::MatrixXd nominal_rtest_jacobian(const std::vector<RtestPose>& poses, int nests,
                                       const EffectModel& fx) {
  const RtestReadingsModel model(poses, nests, fx);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(model.num_parameters());
  Eigen::VectorXd r(model.num_residuals());
  Eigen::MatrixXd J(model.num_residuals(), model.num_parameters());
  model.evaluate(x, r, &J);
  return J;
}

std::string v3(const Eigen::Vector3d& v) {
  return "(" + fmt(v[0]) + ", " + fmt(v[1]) + ", " + fmt(v[2]) + ") mm";
}

}  // namespace

RtestSeparationDesign design_rtest_separation(const RtestSession& session,
                                              const std::vector<Effect>& pair,
                                              const RtestSeparationOptions& o) {
  using design_detail::canonical_correlation;
  using design_detail::invert_information;
  using design_detail::Inverted;
  if (pair.size() != 2 || pair[0] == pair[1])
    throw InvalidArgument("design rtest: --separate needs two different effects (EFFECT,EFFECT)");
  if (session.samples.empty())
    throw InvalidArgument("design rtest: --after: the session has no samples");
  if (session.machine != MachineType::BC_trt)
    throw InvalidArgument("design rtest: --after: the session is not of a BC-trt machine");
  if (o.nest_radius_mm.empty() || o.nest_angle_deg.empty() || o.nest_height_mm.empty() ||
      o.b_step_deg.empty() || o.c_step_deg.empty())
    throw InvalidArgument(
        "design rtest: --radii, --nest-angles, --heights, --b-steps and --c-steps need at least "
        "one value each");
  for (double v : o.b_step_deg)
    if (!(v > 0.0)) throw InvalidArgument("design rtest: --b-steps must be > 0 deg");
  for (double v : o.c_step_deg)
    if (!(v > 0.0 && v < 360.0))
      throw InvalidArgument("design rtest: --c-steps must be in (0, 360) deg");
  if (!(o.max_added_time_s > 0.0) || !std::isfinite(o.max_added_time_s))
    throw InvalidArgument("design rtest: --max-time must be > 0 s");
  if (!(o.max_correlation > 0.0 && o.max_correlation < 1.0))
    throw InvalidArgument("design rtest: --max-correlation must be in (0, 1)");
  if (!(o.noise_um >= 0.0) || !std::isfinite(o.noise_um))
    throw InvalidArgument("design rtest: --noise must be >= 0 um");
  if (!(o.dwell_s >= 0.0) || !std::isfinite(o.dwell_s))
    throw InvalidArgument("design rtest: --dwell must be >= 0 s");
  if (!(o.b_limits_deg[0] < o.b_limits_deg[1]))
    throw InvalidArgument("design rtest: --b-limits must be min < max deg");
  const MachineType m = MachineType::BC_trt;
  RtestSeparationDesign D;
  D.effects = {pair[0].id(), pair[1].id()};
  EffectModel fx;
  fx.effects = pair;
  fx.linear_reference = mean_commanded_xyz(session.samples);
  const double t_end = session.samples.back().time;
  D.motion = table_motion_overlap(m, pair[0], pair[1], o.b_limits_deg, t_end + o.max_added_time_s,
                                  o.reference_radius_mm);

  // The session's poses and noise (the R-test joint fit's residual noise model).
  std::map<std::string, int> nest_index;
  std::vector<RtestPose> poses;
  for (const RtestSample& s : session.samples) {
    const auto it = session.nests.find(s.setup);
    if (it == session.nests.end())
      throw InvalidArgument("design rtest: --after: nest '" + s.setup + "' has no position");
    const int k = nest_index.emplace(s.setup, static_cast<int>(nest_index.size())).first->second;
    poses.push_back({k, it->second, s.xyz, s.angles_rad(), s.time, Eigen::Vector3d::Zero()});
  }
  const int ns = static_cast<int>(nest_index.size()), na = pair[0].num_params(),
            nb = pair[1].num_params();
  const int ne = na + nb, e0 = 8 + 3 * ns, p0 = e0 + ne;  // errors, probe zeros (3 per nest), effects
  RtestJointOptions fo;
  fo.noise = NoiseHandling::white;
  const RtestJointIdentification id = identify_joint(session, fo);
  double sigma_um = o.noise_um > 0.0 ? o.noise_um : id.noise.sigma_um;
  if (!(sigma_um > 0.0)) sigma_um = id.sigma_um;
  if (!(sigma_um > 0.0))
    throw InvalidArgument("design rtest: --after: the session's residuals are zero; give --noise");
  D.noise_um = sigma_um;
  if (id.noise.n > 0 && id.noise.effective_samples > 0.0)
    D.effective_per_reading =
        std::min(1.0, id.noise.effective_samples / static_cast<double>(id.noise.n));
  const double w = D.effective_per_reading / (sigma_um * sigma_um * 1e-6);
  const Eigen::MatrixXd Js = nominal_rtest_jacobian(poses, ns, fx);
  const Eigen::MatrixXd Is = Js.transpose() * Js * w;
  for (int k = 0; k < 8; ++k)
    D.names.push_back(location_error_names(m)[static_cast<std::size_t>(k)]);
  std::vector<std::string> nest_names(static_cast<std::size_t>(ns));
  for (const auto& [name, k] : nest_index) nest_names[static_cast<std::size_t>(k)] = name;
  for (const std::string& n : nest_names)
    for (const char* c : {"zero_x#", "zero_y#", "zero_z#"}) D.names.push_back(c + n);
  for (const std::string& l : fx.param_labels()) D.names.push_back(l);
  Eigen::VectorXd plausible = Eigen::VectorXd::Constant(p0 + 3, plausible_magnitude("mm"));
  for (int k = 0; k < 8; ++k)
    plausible[k] = plausible_magnitude(location_error_is_angle(k) ? "rad" : "mm");
  {
    int j = e0;
    for (const Effect& f : pair)
      for (const std::string& u : f.param_units()) plausible[j++] = plausible_magnitude(u);
  }
  const double white = 1.0 / D.effective_per_reading;
  const Inverted before = invert_information(Is, plausible.head(p0), white);
  D.sigma_before = before.sigma;
  D.correlation_before = canonical_correlation(before, e0, na, e0 + na, nb);
  D.sigma_after = D.sigma_before;
  D.chosen.correlation = D.correlation_before;
  if (D.motion.same_motion) {
    D.verdict =
        "no test can separate " + D.effects[0] + " and " + D.effects[1] + ": " + D.motion.why;
    return D;
  }
  if (D.correlation_before < o.max_correlation) {
    D.already_separated = true;
    std::ostringstream v;
    v.precision(2);
    v << std::fixed << "the session alone separates " << D.effects[0] << " and " << D.effects[1]
      << " (correlation " << D.correlation_before << " < " << o.max_correlation
      << "): no added test is needed";
    D.verdict = v.str();
    return D;
  }
  double dwell = o.dwell_s;
  if (!(dwell > 0.0)) {
    std::vector<double> dt;
    for (std::size_t i = 1; i < session.samples.size(); ++i)
      if (session.samples[i].setup == session.samples[i - 1].setup)
        dt.push_back(session.samples[i].time - session.samples[i - 1].time);
    std::sort(dt.begin(), dt.end());
    dwell = dt.empty() || !(dt[dt.size() / 2] > 0.0) ? RtestPattern{}.dwell_s : dt[dt.size() / 2];
  }

  const double deg = M_PI / 180.0;
  bool have_best = false, have_fallback = false;
  Eigen::MatrixXd best_info;
  for (double r : o.nest_radius_mm)
    for (double ang : o.nest_angle_deg)
      for (double h : o.nest_height_mm) {
        if (r == 0.0 && ang != o.nest_angle_deg.front()) continue;  // one nest on the axis
        Eigen::Vector3d q(r * std::cos(ang * deg), r * std::sin(ang * deg), h);
        q = (q * 1e9).array().round() / 1e9;  // cos 90 deg is 6e-17, not 0
        for (double bs : o.b_step_deg)
          for (double cs : o.c_step_deg) {
            RtestPattern pat;
            pat.nests = {q};
            pat.b_deg = steps(o.b_limits_deg[0], o.b_limits_deg[1], bs);
            pat.c_deg = steps(0.0, 360.0 - cs, cs);
            pat.dwell_s = dwell;
            const double duration =
                static_cast<double>(pat.b_deg.size() * pat.c_deg.size()) * dwell;
            if (duration > o.max_added_time_s) continue;
            std::vector<RtestPose> added;
            bool inside = true;
            double t = t_end;
            for (double b : pat.b_deg)
              for (double c : pat.c_deg) {
                const RotaryAngles<double> a{b * deg, c * deg};
                const Eigen::Vector3d xyz = rtest_commanded_xyz(m, q, a);
                for (int k = 0; k < 3; ++k)
                  inside = inside && xyz[k] >= o.travel_min[k] && xyz[k] <= o.travel_max[k];
                added.push_back({0, q, xyz, a, t += dwell, Eigen::Vector3d::Zero()});
              }
            if (!inside) continue;
            ++D.candidates_tried;
            // Added columns: 8 location, its probe zero, effects -> joint layout.
            const Eigen::MatrixXd Ja = nominal_rtest_jacobian(added, 1, fx);
            const int p = p0 + 3;
            Eigen::MatrixXd Jm = Eigen::MatrixXd::Zero(Ja.rows(), p);
            Jm.leftCols(8) = Ja.leftCols(8);
            Jm.middleCols(p0, 3) = Ja.middleCols(8, 3);
            Jm.middleCols(e0, ne) = Ja.middleCols(11, ne);
            const Eigen::MatrixXd Ia = Jm.transpose() * Jm * w;
            Eigen::MatrixXd I0 = Eigen::MatrixXd::Zero(p, p);
            I0.topLeftCorner(p0, p0) = Is;
            for (double rep = 1.0; duration * rep <= o.max_added_time_s * (1 + 1e-12); rep *= 2.0) {
              const Eigen::MatrixXd I = I0 + rep * Ia;
              const Inverted inv = invert_information(I, plausible, white);
              RtestSeparatingCandidate c;
              c.added = pat;
              c.duration_s = duration;
              c.repeats = rep;
              c.correlation = canonical_correlation(inv, e0, na, e0 + na, nb);
              c.determined = true;
              for (int j = e0; j < e0 + ne; ++j)
                c.determined = c.determined && inv.determined[static_cast<std::size_t>(j)];
              const double run = duration * rep;
              if (c.correlation < o.max_correlation) {
                const double best_run = D.chosen.duration_s * D.chosen.repeats;
                if (!have_best || run < best_run - 1e-9 ||
                    (std::abs(run - best_run) <= 1e-9 && c.correlation < D.chosen.correlation)) {
                  D.chosen = c;
                  best_info = I;
                  have_best = true;
                }
                break;
              }
              if (!have_best && (!have_fallback || c.correlation < D.chosen.correlation)) {
                D.chosen = c;
                best_info = I;
                have_fallback = true;
              }
            }
          }
      }
  D.found = have_best;
  if (have_best || have_fallback) {
    RtestSeparatingCandidate& c = D.chosen;
    const RtestPattern& pat = c.added;
    std::ostringstream d;
    d << "a nest at " << v3(pat.nests[0]) << ", B " << fmt(pat.b_deg.front(), 0) << ".."
      << fmt(pat.b_deg.back(), 0) << " deg every "
      << fmt(pat.b_deg.size() > 1 ? pat.b_deg[1] - pat.b_deg[0] : 0.0, 0) << ", C every "
      << fmt(pat.c_deg.size() > 1 ? pat.c_deg[1] - pat.c_deg[0] : 360.0, 0) << " deg, "
      << fmt(pat.dwell_s, 1) << " s per pose";
    if (c.repeats > 1.0) d << ", run " << fmt(c.repeats, 0) << " times";
    c.description = d.str();
    D.sigma_after = invert_information(best_info, plausible, white).sigma;
    for (const char* n : {"zero_x#added", "zero_y#added", "zero_z#added"}) D.names.push_back(n);
  }
  std::ostringstream v;
  v.precision(2);
  v << std::fixed;
  if (D.found)
    v << "add " << D.chosen.description << ": " << fmt(D.chosen.duration_s * D.chosen.repeats, 0)
      << " s; fitted with the session, the correlation of " << D.effects[0] << " and "
      << D.effects[1] << " goes from " << D.correlation_before << " to " << D.chosen.correlation;
  else
    v << "none of " << D.candidates_tried << " added nests within " << fmt(o.max_added_time_s, 0)
      << " s brings the correlation of " << D.effects[0] << " and " << D.effects[1] << " below "
      << o.max_correlation
      << (D.candidates_tried ? "; the closest is " + D.chosen.description + " (correlation " +
                                   fmt(D.chosen.correlation, 2) + ")"
                             : std::string("; every candidate breaks a limit"));
  if (D.candidates_tried) {
    std::string held;
    for (int j = e0; j < e0 + ne; ++j)
      if (!std::isfinite(D.sigma_after[j]))
        held += (held.empty() ? "" : ", ") + D.names[static_cast<std::size_t>(j)];
    if (!held.empty())
      v << "; " << held
        << " remain undetermined (no reading sees them: the joint fit holds them at 0, and the "
           "correlation is that of "
           "the rest)";
  }
  D.verdict = v.str();
  return D;
}

JointFitOutcome identify_rtest_effects(const RtestSession& session, const EffectModel& effects) {
  if (session.machine != MachineType::BC_trt)
    throw InvalidArgument("identify_rtest_effects: the session is not of a BC-trt machine");
  for (const Effect& f : effects.effects)
    if (!f.applies_to(session.machine))
      throw InvalidArgument("effect " + f.id() + " does not exist on a BC-trt");
  std::map<std::string, int> nest_index;
  std::vector<RtestPose> poses;
  for (const RtestSample& s : session.samples) {
    const auto it = session.nests.find(s.setup);
    if (it == session.nests.end())
      throw InvalidArgument("identify_rtest_effects: nest '" + s.setup + "' has no position");
    if (!s.d)
      throw InvalidArgument("identify_rtest_effects: a sample of nest '" + s.setup +
                            "' has no dx, dy, dz");
    const int k = nest_index.emplace(s.setup, static_cast<int>(nest_index.size())).first->second;
    poses.push_back({k, it->second, s.xyz, s.angles_rad(), s.time, *s.d});
  }
  const int ns = static_cast<int>(nest_index.size());
  std::vector<std::string> names(static_cast<std::size_t>(ns));
  for (const auto& [name, k] : nest_index) names[static_cast<std::size_t>(k)] = name;
  std::vector<FitParameter> params;
  for (int k = 0; k < 8; ++k)
    params.push_back({location_error_names(MachineType::BC_trt)[static_cast<std::size_t>(k)],
                      location_error_is_angle(k) ? "rad" : "mm", 0.0});
  for (const std::string& n : names)
    for (const char* c : {"zero_x#", "zero_y#", "zero_z#"}) params.push_back({c + n, "mm", 0.0});
  for (const Effect& f : effects.effects) {
    const auto pn = f.param_names(), pu = f.param_units();
    for (std::size_t k = 0; k < pn.size(); ++k)
      params.push_back({f.id() + (pn.size() > 1 ? "." + pn[k] : ""), pu[k], 0.0});
  }
  const RtestReadingsModel model(std::move(poses), ns, centred_on(effects, session.samples));
  JointFitSettings settings;
  settings.sigma = session.noise_um.value_or(1.0) * 1e-3;
  return solve_joint(model, params, settings);
}

}  // namespace rotacal
