// SPDX-License-Identifier: BSD-3-Clause
// R-test joint fit: smooth basis of the error maps, the joint model's readings with their
// uncertainty, and the fit through the one joint-fit driver (core/joint_fit.hpp).
#include "rotacal/rtest/identify_joint.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/joint_fit.hpp"
#include "rotacal/rtest/problem.hpp"

namespace rotacal {

namespace {
const char* kCompNames[6] = {"dx", "dy", "dz", "alpha", "beta", "gamma"};
}

// ---------------------------------------------------------------- basis
int RtestBasis::num_b_coefficients() const {
  int n = 0;
  for (int k = 0; k < 6; ++k) n += static_cast<int>(b_terms(k, 0.3).size());
  return n;
}
int RtestBasis::num_c_coefficients() const {
  return static_cast<int>(coefficient_names().size()) - num_b_coefficients();
}
namespace {
// The C-map terms: (component k, harmonic n, cos/sin, power m), except that for the pairs
// (dx, dy) and (alpha, beta) at n = 1, m = 0 only the backward-turning motion
// (u cos C + v sin C, -u sin C + v cos C) is kept (see the header). Calls f(name, term), `name`
// a callable that makes the term's name: the basis is evaluated at every pose of a fit, where
// building the names took a third of the R-test joint fit's time.
template <typename F>
void for_each_c_term(const RtestBasis& bs, double B, double C, const std::string& map, F f) {
  const double b = B / (M_PI / 2.0);
  for (int k = 0; k < (bs.gamma_cb ? 6 : 5); ++k) {
    if (k >= 3 && !bs.c_rotations) break;
    for (int n = 1; n <= bs.c_harmonics; ++n) {
      double bm = 1.0;
      for (int m = 0; m <= bs.c_b_degree; ++m, bm *= b)
        for (int cs = 0; cs < 2; ++cs) {
          AxisErrors<double> t = AxisErrors<double>::Zero();
          const bool pair = k == 0 || k == 1 || k == 3 || k == 4;
          if (pair && n == 1 && m == 0) {
            if (k == 1 || k == 4) continue;  // carried by the pair's first component
            // Backward relative to the axis' own turning: about -Z that is +C in X, Y.
            const double c = std::cos(C), s = bs.c_reversed ? -std::sin(C) : std::sin(C);
            t[k] = cs == 0 ? c : s;
            t[k + 1] = cs == 0 ? -s : c;
            f(
                [&] {
                  return std::string(k == 0 ? "dxy" : "alphabeta") + "_" + map + ".back1." +
                         (cs == 0 ? "u" : "v") + ".b0";
                },
                t);
            continue;
          }
          t[k] = bm * (cs == 0 ? std::cos(n * C) : std::sin(n * C));
          f(
              [&] {
                return std::string(kCompNames[k]) + "_" + map + "." + (cs == 0 ? "cos" : "sin") +
                       std::to_string(n) + ".b" + std::to_string(m);
              },
              t);
        }
    }
  }
}
}  // namespace
std::vector<AxisErrors<double>> RtestBasis::c_terms(double B, double C) const {
  std::vector<AxisErrors<double>> out;
  for_each_c_term(*this, B, C, "CB",
                  [&](const auto&, const AxisErrors<double>& t) { out.push_back(t); });
  return out;
}
std::vector<double> RtestBasis::b_terms(int k, double B) const {
  const double b = B / (M_PI / 2.0);
  std::vector<double> out;
  if (k >= 3 && !b_rotations) return out;
  for (int p = (k < 3 ? 2 : 1); p <= b_degree; p += 2) out.push_back(std::pow(b, p));
  return out;
}
namespace {
// Names of this basis' coefficients (its own rotation flags) with the given map names.
std::vector<std::string> basis_names(const RtestBasis& bs, const std::array<std::string, 2>& maps) {
  std::vector<std::string> out;
  for (int k = 0; k < (bs.b_rotations ? 6 : 3); ++k)
    for (int p = (k < 3 ? 2 : 1); p <= bs.b_degree; p += 2)
      out.push_back(std::string(kCompNames[k]) + "_" + maps[0] + ".b" + std::to_string(p));
  for_each_c_term(bs, 0.3, 0.7, maps[1],
                  [&](const auto& name, const AxisErrors<double>&) { out.push_back(name()); });
  return out;
}
}  // namespace
std::vector<std::string> RtestBasis::coefficient_names() const {
  return basis_names(*this, {"BY", "CB"});
}
std::vector<std::string> RtestBasis::coefficient_names(MachineType m) const {
  return basis_names(for_machine(m), rtest_map_names(m));
}

void RtestBasis::map_rows(double B, double C, Eigen::Ref<Eigen::MatrixXd> Lb,
                          Eigen::Ref<Eigen::MatrixXd> Lc) const {
  Lb.setZero();
  Lc.setZero();
  Eigen::Index o = 0;
  for (int k = 0; k < 6; ++k)
    for (double phi : b_terms(k, B)) Lb(k, o++) = phi;
  o = 0;
  for (const AxisErrors<double>& t : c_terms(B, C)) Lc.col(o++) = t;
}

RtestBasis RtestBasis::for_machine(MachineType m) const {
  RtestBasis out = *this;
  out.b_rotations = !m.description().axis(m.tilt_index()).on_head;
  out.c_rotations = !m.description().axis(m.rot_index()).on_head;
  out.c_reversed = m.description().axis(m.rot_index()).direction.z() < 0.0;
  return out;
}

// ---------------------------------------------------------------- model
namespace {
// The model's params: the R-test problem's layout without probe zeros and effects.
RtestLayout model_layout(const RtestJointModel& m) {
  return rtest_layout(m.machine, {}, &m.basis, EffectModel{});
}
LocationErrors<double> errors_at(const RtestLayout& L, const Eigen::VectorXd& p) {
  return LocationErrors<double>(L.errors.of<8>(p));
}
double tool_offset_z_at(const RtestLayout& L, const Eigen::VectorXd& p) {
  return L.tool.empty() ? 0.0 : p[L.tool.offset];
}

// Linear map from params to w_BY (6 x P) and w_CB (6 x P) at (B, C).
void map_rows(const RtestJointModel& m, const RtestLayout& L, double B, double C,
              Eigen::MatrixXd& Lb, Eigen::MatrixXd& Lc) {
  Lb = Eigen::MatrixXd::Zero(6, m.params.size());
  Lc = Eigen::MatrixXd::Zero(6, m.params.size());
  m.basis.for_machine(m.machine).map_rows(B, C, L.map_tilt.columns(Lb), L.map_rot.columns(Lc));
}

AxisErrors<double> propagate(const RtestJointModel& m, const Eigen::MatrixXd& L) {
  AxisErrors<double> s;
  for (int k = 0; k < 6; ++k) {
    bool ok = true;
    for (Eigen::Index j = 0; j < L.cols(); ++j)
      if (L(k, j) != 0.0 && !m.observable[static_cast<std::size_t>(j)]) ok = false;
    s[k] = ok ? std::sqrt(std::max(0.0, double(L.row(k) * m.covariance * L.row(k).transpose())))
              : std::numeric_limits<double>::quiet_NaN();
  }
  return s;
}

// 1-sigma of a function f(params) by central differences (the model is linear to well below
// the noise over the identified magnitudes).
template <typename F>
Eigen::Vector3d propagate_fn(const RtestJointModel& m, const RtestLayout& L, F f) {
  const int P = static_cast<int>(m.params.size());
  Eigen::MatrixXd J(3, P);
  Eigen::VectorXd t = m.params;
  for (int j = 0; j < P; ++j) {
    const bool angle =
        L.errors.contains(j) && location_error_is_angle(static_cast<int>(j - L.errors.offset));
    const double h = angle ? 1e-7 : 1e-5;
    t = m.params;
    t[j] += h;
    const Eigen::Vector3d fp = f(t);
    t[j] -= 2 * h;
    J.col(j) = (fp - f(t)) / (2 * h);
  }
  Eigen::Vector3d s;
  for (int r = 0; r < 3; ++r) {
    bool ok = true;
    for (int j = 0; j < P; ++j)
      if (std::abs(J(r, j)) > 1e-9 && !m.observable[static_cast<std::size_t>(j)]) ok = false;
    s[r] = ok ? std::sqrt(std::max(0.0, double(J.row(r) * m.covariance * J.row(r).transpose())))
              : std::numeric_limits<double>::quiet_NaN();
  }
  return s;
}

Pose<double> table_pose_at(const RtestJointModel& m, const RtestLayout& L,
                           const Eigen::VectorXd& params, double B, double C) {
  const double* p = params.data();
  return rtest_joint_table_pose<double>(m.machine, m.basis, L.errors.ptr(p), p + L.map_tilt.offset,
                                        p + L.map_rot.offset, B, C);
}
}  // namespace

std::vector<std::string> RtestJointModel::parameter_names() const {
  return model_layout(*this).all.names();
}
LocationErrors<double> RtestJointModel::errors() const {
  return errors_at(model_layout(*this), params);
}
double RtestJointModel::tool_offset_z() const {
  return tool_offset_z_at(model_layout(*this), params);
}

AxisErrors<double> RtestJointModel::w_BY(double B, AxisErrors<double>* std) const {
  Eigen::MatrixXd Lb, Lc;
  map_rows(*this, model_layout(*this), B, 0.0, Lb, Lc);
  if (std) *std = propagate(*this, Lb);
  return Lb * params;
}
AxisErrors<double> RtestJointModel::w_CB(double B, double C, AxisErrors<double>* std) const {
  Eigen::MatrixXd Lb, Lc;
  map_rows(*this, model_layout(*this), B, C, Lb, Lc);
  if (std) *std = propagate(*this, Lc);
  return Lc * params;
}
Pose<double> RtestJointModel::table_pose(double B, double C) const {
  return table_pose_at(*this, model_layout(*this), params, B, C);
}
Eigen::Vector3d RtestJointModel::reading(const Eigen::Vector3d& q, double B, double C,
                                         Eigen::Vector3d* std) const {
  const Eigen::Vector3d xyz = rtest_commanded_xyz(machine, q, {B, C});
  const RtestLayout L = model_layout(*this);
  Eigen::MatrixXd Lb, Lc;  // the maps' rows at (B, C), once for every difference
  map_rows(*this, L, B, C, Lb, Lc);
  auto f = [&](const Eigen::VectorXd& p) {
    return Eigen::Vector3d(rtest_joint_reading<double>(machine, errors_at(L, p), Lb * p, Lc * p,
                                                       tool_offset_z_at(L, p), {B, C}, xyz, q));
  };
  if (std) *std = propagate_fn(*this, L, f);
  return f(params);
}
Eigen::Vector3d RtestJointModel::table_error(const Eigen::Vector3d& q, double B, double C,
                                             Eigen::Vector3d* std) const {
  const RtestLayout L = model_layout(*this);
  auto f = [&](const Eigen::VectorXd& p) {
    return Eigen::Vector3d(table_pose_at(*this, L, p, B, C) * q -
                           forward<double>(machine, LocationErrors<double>(), {B, C}, q));
  };
  if (std) *std = propagate_fn(*this, L, f);
  return f(params);
}
Eigen::Vector3d RtestJointModel::tool_error(const Eigen::Vector3d& xyz, double B, double C,
                                            Eigen::Vector3d* std) const {
  const RtestLayout L = model_layout(*this);
  Eigen::MatrixXd Lb, Lc;
  map_rows(*this, L, B, C, Lb, Lc);
  auto f = [&](const Eigen::VectorXd& p) -> Eigen::Vector3d {
    if (!machine.has_head()) return Eigen::Vector3d::Zero();
    const Pose<double> H =
        rtest_joint_side_pose<double>(machine, errors_at(L, p), Lb * p, Lc * p, {B, C}, true);
    return xyz + H * tool_vector<double>(machine, -tool_offset_z_at(L, p)) -
           tool_ball<double>(machine, LocationErrors<double>(), {B, C}, xyz);
  };
  if (std) *std = propagate_fn(*this, L, f);
  return f(params);
}

// ---------------------------------------------------------------- fit
namespace {
// True when the tilt axis carries the rotary axis on the same side of the chain.
bool m_tilt_carries_rot(MachineType m) {
  const MachineDescription& d = m.description();
  return d.axis(0).on_head == d.axis(1).on_head && m.tilt_index() == 0;
}

// Which set-up change would show what this session cannot (the unobservable combinations in
// words, core/least_squares.hpp), in the spirit of the ballbar's advice.
std::vector<std::string> rtest_setup_advice(MachineType m,
                                            const std::vector<std::string>& unobservable) {
  std::vector<std::string> out;
  if (unobservable.empty()) return out;
  auto mentions = [&](const std::string& name) {
    for (const std::string& u : unobservable)
      if (u.find(name) != std::string::npos) return true;
    return false;
  };
  const auto& names = location_error_names(m);
  const std::array<std::string, 2> maps = rtest_map_names(m);
  const MachineDescription& d = m.description();
  bool head_advised = false;
  if (mentions("tool_offset_Z")) {
    out.push_back(
        "pivot_length + tool_length (tool_offset_Z) is seen together with a head axis' position "
        "along the spindle: a second tool length (the sphere at a second distance from the "
        "head) separates them");
    head_advised = true;
  }
  for (int k = 0; k < 2; ++k) {
    const RotaryAxis& a = d.axis(k);
    const std::string map = maps[k == m.tilt_index() ? 0 : 1];
    bool seen = mentions("_" + map + ".");
    for (int j = 0; j < 4; ++j) seen |= mentions(names[static_cast<std::size_t>(4 * k + j)]);
    if (!seen) continue;
    if (a.on_head) {
      if (!head_advised)
        out.push_back(
            std::string("errors of the head axis ") + a.name + " (location errors, map " + map +
            ") are seen as one movement of the sphere at one tool length: a second tool length "
            "(the rotations' effect scales with it, a translation's does not) separates them");
      head_advised = true;
    } else {
      out.push_back(
          std::string("errors of the table axis ") + a.name + " (location errors, map " + map +
          ") are seen together at these nests: a nest at a second height and a second distance "
          "from the " +
          a.name + " line separates them");
    }
  }
  return out;
}
}  // namespace

RtestJointIdentification identify_joint(const RtestSession& session,
                                        const RtestJointOptions& options) {
  const MachineType machine = session.machine;
  const RtestBasis basis = options.basis.for_machine(machine);
  if (basis.b_degree < 0 || basis.c_harmonics < 0 || basis.c_b_degree < 0)
    throw InvalidArgument("identify_joint: options.basis: degrees and harmonics must be >= 0");
  const RtestArrays data = rtest_arrays(session, "identify_joint");
  const std::vector<std::string>& setups = data.setups;
  const RtestProblem model(data, &basis, EffectModel{});
  const RtestLayout& L = model.layout();
  const Eigen::Index n_par = L.all.size(), n_model = L.zeros.offset;
  if (3 * static_cast<Eigen::Index>(session.samples.size()) <= n_par)
    throw InvalidArgument("identify_joint: session: " + std::to_string(3 * session.samples.size()) +
                          " readings cannot determine " + std::to_string(n_par) + " unknowns");

  // The unknowns start at zero, except each probe zero: at its set-up's mean reading (the
  // closed-form answer for zero errors).
  std::vector<FitParameter> params;
  const std::vector<std::string> names = L.all.names(), units = L.all.units();
  for (std::size_t j = 0; j < names.size(); ++j) params.push_back({names[j], units[j], 0.0});
  for (std::size_t k = 0; k < setups.size(); ++k) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    const auto idx = session.indices_of(setups[k]);
    for (std::size_t i : idx) mean += *session.samples[i].d;
    mean /= static_cast<double>(idx.size());
    for (int a = 0; a < 3; ++a)
      params[static_cast<std::size_t>(L.zeros.item_offset(static_cast<Eigen::Index>(k)) + a)]
          .start = mean[a];
  }

  JointFitSettings settings;
  settings.max_iterations = options.max_iterations;
  settings.observability_min_chi2 = options.observability_min_chi2;
  settings.sigma = session.noise_um.value_or(1.0) * 1e-3;  // scales chi-square only
  settings.whitener = options.whitener;

  // Noise model of the residuals: one AR stream per nest and channel (dx, dy, dz share a
  // time, so the estimator splits them), in time order. Probe zeros that wander between
  // poses and servo/thermal noise make it correlated; then the fit is redone by GLS under the
  // model (core/fit_with_noise.hpp), AR(1) + a random walk per stream by REML: the probe zeros
  // and the B polynomials (B runs outer) take most of a walk out of the residuals, which
  // Burg's AR(p) of the residuals cannot see (docs/noise_model.md).
  std::vector<std::string> groups;
  std::vector<double> times;
  groups.reserve(3 * session.samples.size());
  times.reserve(3 * session.samples.size());
  for (const RtestSample& s : session.samples)
    for (int a = 0; a < 3; ++a) {
      groups.push_back("nest " + s.setup);
      times.push_back(s.time);
    }
  NoiseFit nf =
      fit_with_noise([&](const JointFitSettings& s) { return solve_joint(model, params, s); },
                     settings, groups, times, options.noise);
  const std::string gls_note = noise_refit_note(nf);
  const Eigen::VectorXd values = nf.fit.values;
  RtestJointIdentification out;
  static_cast<Identification&>(out) =
      joint_identification(std::move(nf), L.all, options.whitener != nullptr, true);
  out.n_samples = session.samples.size();
  for (std::size_t k = 0; k < setups.size(); ++k)
    out.probe_zeros[setups[k]] =
        values.segment<3>(L.zeros.item_offset(static_cast<Eigen::Index>(k)));
  for (std::string& advice : rtest_setup_advice(machine, out.unobservable))
    out.notes.push_back(std::move(advice));
  if (!gls_note.empty()) out.notes.push_back(gls_note);

  out.model.machine = machine;
  out.model.basis = basis;
  out.model.params = values.head(n_model);
  out.model.covariance = out.covariance.topLeftCorner(n_model, n_model);
  out.model.observable.clear();
  for (Eigen::Index j = 0; j < n_model; ++j)
    out.model.observable.push_back(out.parameters[static_cast<std::size_t>(j)].observable);

  out.notes.push_back("probe zero per set-up fitted: no reading is assumed to be zero");
  const std::array<std::string, 2> maps = rtest_map_names(machine);
  const std::string tl(1, tilt_axis_letter(machine)), rl(1, rot_axis_letter(machine));
  out.notes.push_back(
      tl + " map (" + maps[0] + "): " +
      (basis.b_rotations ? "even powers of " + tl +
                               " for translations, odd for rotations (separates it from the " + tl +
                               " axis' location errors)"
                         : "even powers of " + tl +
                               " for translations only (a head axis: the sphere is one point)") +
      "; " + rl + " map (" + maps[1] + "): harmonics 1.." + std::to_string(basis.c_harmonics) +
      " of " + rl + (basis.c_rotations ? "" : ", translations only (a head axis)") +
      ", polynomial of degree " + std::to_string(basis.c_b_degree) + " in " + tl);
  if (!basis.gamma_cb && basis.c_rotations)
    out.notes.push_back("gamma_" + maps[1] + " not fitted (assumed zero, as Oyama Sec. 4.2)");
  // A constant offset of the tilt axis turns the rotary axis it carries: a tilt of that axis.
  const bool tilt_carries_rot = m_tilt_carries_rot(machine);
  out.notes.push_back(
      "rotary zero offsets E_" + tl + "0" + tl + ", E_" + rl + "0" + rl +
      " are not in the model: an R-test with the probe zero unknown cannot see a constant " + rl +
      " offset" +
      (tilt_carries_rot ? "; E_" + tl + "0" + tl + " acts as a tilt of the " + rl + " axis" : ""));
  if (machine.has_head())
    out.notes.push_back(
        "tool_offset_Z: minus the error of pivot_length + tool_length, along the spindle");
  if (!out.converged) out.notes.push_back("the fit did not converge: " + out.summary.message);
  return out;
}

}  // namespace rotacal
