// SPDX-License-Identifier: BSD-3-Clause
// One identification from several sessions of one machine (multi/identify.hpp).
#include "rotacal/multi/identify.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>

#include "rotacal/core/block_whitener.hpp"
#include "rotacal/core/parameter_layout.hpp"
#include "rotacal/core/stats.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"
#include "rotacal/session/probe_session.hpp"
#include "rotacal/session/session.hpp"
#include "session_parts.hpp"

namespace rotacal {

using multi_detail::SessionPart;

MultiSessionInput MultiSessionInput::of(std::string name, BallbarSession session) {
  MultiSessionInput in;
  in.name = std::move(name);
  in.instrument = "ballbar";
  in.ballbar = std::make_shared<const BallbarSession>(std::move(session));
  return in;
}
MultiSessionInput MultiSessionInput::of(std::string name, RtestSession session) {
  MultiSessionInput in;
  in.name = std::move(name);
  in.instrument = "rtest";
  in.rtest = std::make_shared<const RtestSession>(std::move(session));
  return in;
}
MultiSessionInput MultiSessionInput::of(std::string name, ProbeSession session) {
  MultiSessionInput in;
  in.name = std::move(name);
  in.instrument = "probe";
  in.probe = std::make_shared<const ProbeSession>(std::move(session));
  return in;
}
MachineType MultiSessionInput::machine() const {
  if (ballbar) return ballbar->machine;
  if (rtest) return rtest->machine;
  if (probe) return probe->machine;
  throw InvalidArgument("identify: session " + name + " holds no data");
}

const ParameterEstimate& MultiIdentification::location_error(const std::string& name) const {
  const ParameterBlock& E = blocks.block("location_errors");
  for (Eigen::Index j = E.offset; j < E.end(); ++j)
    if (parameters[static_cast<std::size_t>(j)].name == name)
      return parameters[static_cast<std::size_t>(j)];
  throw InvalidArgument("no location error named '" + name + "'");
}

namespace {

// The sessions' residual models stacked row-wise over one parameter vector: the shared blocks
// "location_errors" and "effects" (the catalogue effects fitted for the machine, empty unless
// asked), then each session's own parameters as a block named after it. Each session's own
// model computes its rows and Jacobian; its shared columns land on the shared blocks, its other
// columns on its own, or on those of the same name of the earlier session same_as[k] (>= 0)
// whose set-up it continues.
class StackedModel : public ResidualModel {
 public:
  StackedModel(const std::vector<SessionPart>& parts, const std::vector<int>& same_as,
               MachineType m, const EffectModel& fx)
      : parts_(parts) {
    const auto& arr = location_error_names(m);
    std::vector<std::string> names(arr.begin(), arr.end()), units(names.size());
    for (const Effect& f : fx.effects)
      for (std::size_t k = 0; k < static_cast<std::size_t>(f.num_params()); ++k) {
        names.push_back(effect_parameter_name(f, k));
        units.push_back(f.param_units()[k]);
      }
    for (std::size_t j = 0; j < parts.front().parameters.size(); ++j)
      if (parts.front().shared[j] >= 0 && parts.front().shared[j] < 8)
        units[static_cast<std::size_t>(parts.front().shared[j])] = parts.front().parameters[j].unit;
    errors_ = layout_.add("location_errors", {names.begin(), names.begin() + 8},
                          {units.begin(), units.begin() + 8});
    effects_ =
        layout_.add("effects", {names.begin() + 8, names.end()}, {units.begin() + 8, units.end()});
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const SessionPart& p = parts[k];
      if (std::count_if(p.shared.begin(), p.shared.end(), [](Eigen::Index i) { return i >= 0; }) !=
          static_cast<std::ptrdiff_t>(names.size()))
        throw InvalidArgument("identify: session " + p.name + " does not hold the " +
                              std::to_string(names.size()) +
                              " shared parameters (location errors and effects)");
      std::vector<Eigen::Index> map(p.parameters.size(), -1);
      if (same_as[k] >= 0) map = continued(parts, static_cast<std::size_t>(same_as[k]), p);
      std::vector<std::string> own, own_units;
      for (std::size_t j = 0; j < p.parameters.size(); ++j)
        if (p.shared[j] < 0 && map[j] < 0) {
          own.push_back(p.name + ":" + p.parameters[j].name);
          own_units.push_back(p.parameters[j].unit);
        }
      Eigen::Index next = layout_.add(p.name, own, own_units).offset;
      for (std::size_t j = 0; j < p.parameters.size(); ++j)
        if (p.shared[j] >= 0)
          map[j] = shared_index(p.shared[j]);
        else if (map[j] < 0)
          map[j] = next++;
      maps_.push_back(std::move(map));
      rows_ += p.model->num_residuals();
    }
  }
  /// Index in the joint vector of shared parameter i (location errors, then effects).
  Eigen::Index shared_index(Eigen::Index i) const {
    return i < errors_.size ? errors_.offset + i : effects_.offset + i - errors_.size;
  }
  Eigen::Index num_shared() const { return errors_.size + effects_.size; }
  Eigen::Index num_residuals() const override { return rows_; }
  int num_parameters() const override { return static_cast<int>(layout_.size()); }
  void evaluate(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> r,
                Eigen::MatrixXd* J) const override {
    Eigen::Index row = 0;
    if (J) J->setZero();
    for (std::size_t k = 0; k < parts_.size(); ++k) {
      const ResidualModel& m = *parts_[k].model;
      const std::vector<Eigen::Index>& map = maps_[k];
      const Eigen::Index n = m.num_residuals();
      Eigen::VectorXd xk(static_cast<Eigen::Index>(map.size()));
      for (std::size_t j = 0; j < map.size(); ++j) xk[static_cast<Eigen::Index>(j)] = x[map[j]];
      if (!J) {
        m.evaluate(xk, r.segment(row, n), nullptr);
      } else {
        Eigen::MatrixXd Jk(n, xk.size());
        m.evaluate(xk, r.segment(row, n), &Jk);
        for (std::size_t j = 0; j < map.size(); ++j)
          J->col(map[j]).segment(row, n) += Jk.col(static_cast<Eigen::Index>(j));
      }
      row += n;
    }
  }
  const ParameterLayout& layout() const { return layout_; }
  const ParameterBlock& errors() const { return errors_; }
  const ParameterBlock& effects() const { return effects_; }
  const std::vector<Eigen::Index>& map(std::size_t k) const { return maps_[k]; }

 private:
  // Where p's own parameters of the same name as an own parameter of the earlier session q
  // are in the joint vector (-1: not q's).
  std::vector<Eigen::Index> continued(const std::vector<SessionPart>& parts, std::size_t q,
                                      const SessionPart& p) const {
    std::vector<Eigen::Index> map(p.parameters.size(), -1);
    for (std::size_t j = 0; j < p.parameters.size(); ++j)
      for (std::size_t i = 0; i < parts[q].parameters.size() && p.shared[j] < 0; ++i)
        if (parts[q].shared[i] < 0 && parts[q].parameters[i].name == p.parameters[j].name)
          map[j] = maps_[q][i];
    return map;
  }

  const std::vector<SessionPart>& parts_;
  ParameterLayout layout_;
  ParameterBlock errors_, effects_;
  std::vector<std::vector<Eigen::Index>> maps_;
  Eigen::Index rows_ = 0;
};

// The index of the earlier session each session continues (same_setup_as), -1 for none.
std::vector<int> continued_setups(const std::vector<MultiSessionInput>& sessions) {
  std::vector<int> out;
  for (std::size_t k = 0; k < sessions.size(); ++k) {
    const MultiSessionInput& s = sessions[k];
    int q = -1;
    for (std::size_t i = 0; i < k && !s.same_setup_as.empty(); ++i)
      if (sessions[i].name == s.same_setup_as) q = static_cast<int>(i);
    if (!s.same_setup_as.empty() &&
        (q < 0 || sessions[static_cast<std::size_t>(q)].instrument != s.instrument))
      throw InvalidArgument("identify: session " + s.name + " continues the set-up of " +
                            s.same_setup_as + ", which is no earlier " + s.instrument + " session");
    out.push_back(q);
  }
  return out;
}

void check_sessions(const std::vector<MultiSessionInput>& sessions) {
  if (sessions.size() < 2)
    throw InvalidArgument("identify: a joint identification needs at least two sessions, got " +
                          std::to_string(sessions.size()));
  std::set<std::string> names;
  for (const MultiSessionInput& s : sessions)
    if (!names.insert(s.name).second)
      throw InvalidArgument("identify: session name " + s.name + " given twice");
  const MachineType m = sessions.front().machine();
  for (const MultiSessionInput& s : sessions)
    if (s.machine() != m && to_string(s.machine()) == to_string(m))
      throw InvalidArgument("identify: sessions " + sessions.front().name + " and " + s.name +
                            " name one machine, " + to_string(m) +
                            ", with two different descriptions (axes or lengths differ): a "
                            "joint identification is of one machine; give both its one "
                            "description");
    else if (s.machine() != m)
      throw InvalidArgument("identify: sessions of different machine types: " +
                            sessions.front().name + " is " + to_string(m) + ", " + s.name + " is " +
                            to_string(s.machine()) + "; a joint identification is of one machine");
}

// The session alone: white fit -> its noise model -> [GLS], as its instrument's own fit.
NoiseFit fit_alone(const SessionPart& p, const MultiFitOptions& o) {
  NoiseFitOptions no = o.noise;
  no.allow_reml = o.noise.allow_reml && p.allow_reml;
  no.own_noise = p.own_noise;
  JointFitSettings s = p.settings;
  s.max_iterations = o.max_iterations;
  s.observability_min_chi2 = o.observability_min_chi2;
  return fit_with_noise(
      [&](const JointFitSettings& st) { return solve_joint(*p.model, p.parameters, st); }, s,
      p.groups, p.times, no);
}

// The session's block of the joint whitener: its GLS model (scaled by the bias factor) when its
// fit alone was redone by GLS, else 1 / its residual sigma.
BlockDiagonalWhitener::Block whitener_block(const SessionPart& p, const NoiseFit& nf) {
  BlockDiagonalWhitener::Block b;
  b.rows = p.model->num_residuals();
  if (nf.refit) {
    b.whitener = nf.whitener;
    b.factor = 1.0 / nf.scale;
    return b;
  }
  const double dof = std::max(1.0, static_cast<double>(b.rows - nf.fit.summary.num_free));
  b.factor = 1.0 / std::sqrt(nf.fit.residuals.squaredNorm() / dof);
  return b;
}

// Every comparison of two sessions alone on a parameter both determine, as a candidate.
std::vector<MultiDisagreement> comparisons(const std::vector<MultiSessionResult>& s) {
  std::vector<MultiDisagreement> out;
  for (std::size_t a = 0; a < s.size(); ++a)
    for (std::size_t b = a + 1; b < s.size(); ++b)
      for (std::size_t j = 0; j < s[a].alone.size(); ++j) {
        const ParameterEstimate &ea = s[a].alone[j], &eb = s[b].alone[j];
        if (!ea.observable || !eb.observable) continue;
        MultiDisagreement d;
        d.parameter = ea.name;
        d.unit = ea.unit;
        d.session_a = s[a].name;
        d.session_b = s[b].name;
        d.value_a = ea.value;
        d.value_b = eb.value;
        d.difference = ea.value - eb.value;
        d.sigma = std::hypot(ea.std, eb.std);
        d.z = d.sigma > 0.0 ? d.difference / d.sigma : 0.0;
        // Welch-Satterthwaite: (s_a^2 + s_b^2)^2 / (s_a^4 / nu_a + s_b^4 / nu_b).
        const double va = ea.std * ea.std, vb = eb.std * eb.std;
        const double den = va * va / s[a].dof + vb * vb / s[b].dof;
        d.dof = den > 0.0 ? (va + vb) * (va + vb) / den : std::numeric_limits<double>::infinity();
        out.push_back(d);
      }
  return out;
}

// The |z| beyond which a comparison is a disagreement: Bonferroni's bound over the m
// comparisons made, so that sessions of one machine show any disagreement with probability at
// most alpha (whatever the comparisons' correlation), and never below z_min.
// With `dof` finite the sigma of the difference is itself estimated: the bound is Student's t
// at that dof (a sigma from 40 effective touches makes |z| > 3.3 three times likelier than a
// known one would).
double disagreement_threshold(std::size_t m, const MultiFitOptions& o,
                              double dof = std::numeric_limits<double>::infinity()) {
  if (m == 0) return o.disagreement_z;
  const double p = 1.0 - o.disagreement_alpha / static_cast<double>(m);
  return std::max(o.disagreement_z, stats::t_coverage(p, std::max(dof, 1.0)));
}

// Shared parameter j in the order of each session's `alone` (location errors, then effects):
// its index in the joint vector.
Eigen::Index joint_index(const MultiIdentification& m, std::size_t j) {
  const ParameterBlock& E = m.blocks.block("location_errors");
  const auto k = static_cast<Eigen::Index>(j);
  return k < E.size ? E.offset + k : m.blocks.block("effects").offset + (k - E.size);
}

ParameterEstimate& joint_shared(MultiIdentification& m, std::size_t j) {
  return m.parameters[static_cast<std::size_t>(joint_index(m, j))];
}

// A joint value beyond every session's own on one side (each session's value more than z_max
// of its sigma above it, or each below) is no average of them: reported as each session's
// disagreement with the joint fit. A joint value between sessions that disagree is not this.
void outside_every_session(MultiIdentification& m, double z_max,
                           std::vector<MultiDisagreement>& out) {
  for (std::size_t j = 0; j < m.sessions.front().alone.size(); ++j) {
    const ParameterEstimate& J = joint_shared(m, j);
    if (!J.observable) continue;
    std::vector<MultiDisagreement> sides;
    bool all_above = true, all_below = true;
    for (const MultiSessionResult& s : m.sessions) {
      const ParameterEstimate& e = s.alone[j];
      if (!e.observable) continue;
      MultiDisagreement d;
      d.parameter = J.name;
      d.unit = J.unit;
      d.session_a = s.name;
      d.session_b = kJointFitSide;
      d.value_a = e.value;
      d.value_b = J.value;
      d.difference = e.value - J.value;
      d.sigma = e.std;
      d.z = d.sigma > 0.0 ? d.difference / d.sigma : 0.0;
      all_above = all_above && d.z > z_max;
      all_below = all_below && d.z < -z_max;
      sides.push_back(d);
    }
    if (!sides.empty() && (all_above || all_below))
      out.insert(out.end(), sides.begin(), sides.end());
  }
}

std::string shown(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

// inflate_sigma: each parameter the sessions disagree on gets its sigma (and its covariance
// row and column) widened by its Birge ratio, the scatter of the sessions alone about the
// joint value, sqrt(chi2 / (n - 1)), when that exceeds 1.
void inflate_disagreeing(MultiIdentification& m) {
  std::set<std::string> hit;
  for (const MultiDisagreement& d : m.disagreements) hit.insert(d.parameter);
  for (std::size_t j = 0; j < m.sessions.front().alone.size(); ++j) {
    ParameterEstimate& J = joint_shared(m, j);
    if (!J.observable || hit.count(J.name) == 0) continue;
    double chi2 = 0.0;
    int n = 0;
    for (const MultiSessionResult& s : m.sessions) {
      const ParameterEstimate& e = s.alone[j];
      if (!e.observable || !(e.std > 0.0)) continue;
      chi2 += std::pow((e.value - J.value) / e.std, 2);
      ++n;
    }
    const double r = std::sqrt(chi2 / std::max(1, n - 1));
    if (!(r > 1.0)) continue;
    J.std *= r;
    const Eigen::Index i = joint_index(m, j);
    m.covariance.row(i) *= r;
    m.covariance.col(i) *= r;
    m.notes.push_back("the sigma of " + J.name + " is widened x" + shown(r) +
                      " (Birge ratio of the sessions alone about the joint value) because the "
                      "sessions disagree on it, as asked (inflate sigma)");
  }
  m.sigma_inflated = true;
}

// The shared catalogue effects as every session fits them: their linear-axis polynomials about
// the caller's a_ref, else about the machine zero, the same for every session.
EffectModel shared_effects(const MultiFitOptions& o) {
  EffectModel fx = o.effects;
  if (!fx.linear_reference) fx.linear_reference = Eigen::Vector3d::Zero();
  return fx;
}

}  // namespace

MultiIdentification identify_multi(const std::vector<MultiSessionInput>& sessions,
                                   const MultiFitOptions& o) {
  check_sessions(sessions);
  const EffectModel fx = shared_effects(o);
  std::vector<SessionPart> parts;
  for (const MultiSessionInput& s : sessions) parts.push_back(multi_detail::session_part(s, fx));
  const StackedModel model(parts, continued_setups(sessions), sessions.front().machine(), fx);

  MultiIdentification out;
  out.machine = sessions.front().machine();
  out.effect_model = fx;
  std::vector<BlockDiagonalWhitener::Block> wblocks;
  std::vector<FitParameter> params(static_cast<std::size_t>(model.num_parameters()));
  const std::vector<std::string> names = model.layout().names(), units = model.layout().units();
  for (std::size_t j = 0; j < params.size(); ++j) params[j] = {names[j], units[j], 0.0};
  std::vector<bool> set(params.size(), false);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const SessionPart& p = parts[k];
    const NoiseFit nf = fit_alone(p, o);
    wblocks.push_back(whitener_block(p, nf));
    MultiSessionResult r;
    r.alone.resize(static_cast<std::size_t>(model.num_shared()));
    // Own parameters start at the session's solution alone; the shared ones at zero, with the
    // first session's settings (scale, yield convention of the effects).
    for (std::size_t j = 0; j < p.parameters.size(); ++j) {
      const auto J = static_cast<std::size_t>(model.map(k)[j]);
      if (p.shared[j] >= 0) r.alone[static_cast<std::size_t>(p.shared[j])] = nf.fit.estimates[j];
      if (set[J]) continue;
      params[J] = p.parameters[j];
      params[J].name = names[J];
      params[J].start = p.shared[j] >= 0 ? 0.0 : nf.fit.values[static_cast<Eigen::Index>(j)];
      set[J] = true;
    }
    r.name = p.name;
    r.instrument = p.instrument;
    r.noise = nf.noise;
    r.noise_refit = nf.refit;
    r.noise_correction = nf.scale;
    r.dof =
        std::max(1.0, nf.noise.effective_samples - static_cast<double>(nf.fit.summary.num_free));
    r.n_residuals = static_cast<std::size_t>(p.model->num_residuals());
    out.sessions.push_back(std::move(r));
  }

  JointFitSettings settings;
  settings.max_iterations = o.max_iterations;
  settings.observability_min_chi2 = o.observability_min_chi2;
  settings.whitener = std::make_shared<BlockDiagonalWhitener>(std::move(wblocks));
  NoiseFit joint;
  joint.fit = solve_joint(model, params, settings);
  const JointFitOutcome& fit = joint.fit;
  Eigen::Index row = 0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    for (std::size_t j = 0; j < parts[k].parameters.size(); ++j)
      if (parts[k].shared[j] < 0) {
        out.sessions[k].nuisances.push_back(
            fit.estimates[static_cast<std::size_t>(model.map(k)[j])]);
        out.sessions[k].nuisances.back().name = parts[k].parameters[j].name;
      }
    const Eigen::Index n = static_cast<Eigen::Index>(out.sessions[k].n_residuals);
    const double ms = fit.residuals.segment(row, n).squaredNorm() / static_cast<double>(n);
    out.sessions[k].residual_rms_um = std::sqrt(ms) * 1e3;
    row += n;
  }
  // The common part (estimates, covariance, residuals, solver figures) as every instrument's;
  // the rows are whitened per session, so sigma_um is the dof-corrected level of the raw rows.
  static_cast<Identification&>(out) = joint_identification(std::move(joint), model.layout(), true);
  out.n_samples = out.residuals.size();
  std::vector<MultiDisagreement> all = comparisons(out.sessions);
  out.comparisons = all.size();
  out.disagreement_z = disagreement_threshold(all.size(), o);
  for (MultiDisagreement& d : all) {
    d.threshold = disagreement_threshold(all.size(), o, d.dof);
    if (std::abs(d.z) > d.threshold) out.disagreements.push_back(d);
  }
  outside_every_session(out, out.disagreement_z, out.disagreements);
  for (const MultiDisagreement& d : out.disagreements)
    out.notes.push_back(
        d.session_b == kJointFitSide
            ? "the joint " + d.parameter + " lies outside every session's own value (session " +
                  d.session_a + ": z = " + shown(d.z) + "): it is no average of them"
            : "sessions " + d.session_a + " and " + d.session_b + " disagree on " + d.parameter +
                  " (z = " + shown(d.z) + "): the joint value describes neither of them");
  if (!out.disagreements.empty() && o.inflate_sigma) inflate_disagreeing(out);
  if (!out.converged) out.notes.push_back("the joint fit did not converge: " + out.summary.message);
  return out;
}

}  // namespace rotacal
