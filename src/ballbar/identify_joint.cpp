// SPDX-License-Identifier: BSD-3-Clause
// Joint ballbar fit: the exact length model (model.hpp) over structure-of-arrays samples,
// solved by the one joint-fit driver (core/joint_fit.hpp).
#include <algorithm>
#include <cmath>
#include <memory>
#include <type_traits>

#include "length_model.hpp"
#include "rotacal/ballbar/identify.hpp"
#include "rotacal/core/fit_with_noise.hpp"
#include "rotacal/core/time_constant_fit.hpp"

namespace rotacal {

BallbarArrays ballbar_arrays(const BallbarSession& session, const std::vector<std::string>& tests,
                             bool with_motion) {
  BallbarArrays a;
  a.machine = session.machine;
  a.pivot = session.pivot;
  a.noise_um = session.noise_um;
  a.session_size = session.samples.size();
  for (std::size_t i = 0; i < session.samples.size(); ++i)
    if (tests.empty() ||
        std::find(tests.begin(), tests.end(), session.samples[i].test) != tests.end())
      a.index.push_back(i);
  const Eigen::Index n = static_cast<Eigen::Index>(a.index.size());
  a.xyz.resize(3, n);
  a.angles.resize(a.index.size());
  a.time.resize(n);
  a.length.resize(n);
  a.test.resize(a.index.size());
  // Motion from every row of the session: a test left out still moved the axes.
  const std::vector<RotaryMotion> motion =
      with_motion ? rotary_motion(session.samples) : std::vector<RotaryMotion>{};
  if (with_motion) a.motion.resize(a.index.size());
  for (Eigen::Index k = 0; k < n; ++k) {
    const BallbarSample& s = session.samples[a.index[static_cast<std::size_t>(k)]];
    a.xyz.col(k) = s.xyz;
    a.angles[static_cast<std::size_t>(k)] = s.angles_rad();
    a.time[k] = s.time;
    a.length[k] = s.length;
    a.test[static_cast<std::size_t>(k)] = s.test;
    if (with_motion)
      a.motion[static_cast<std::size_t>(k)] = motion[a.index[static_cast<std::size_t>(k)]];
  }
  return a;
}

BallbarIdentification identify_joint(const BallbarSession& session,
                                     const JointFitOptions& options) {
  // The motion of the axes (rotary_motion) only for effects of the motion.
  const bool with_motion =
      std::any_of(options.effects.effects.begin(), options.effects.effects.end(),
                  [](const Effect& f) { return f.depends_on_motion(); });
  // The linear-axis polynomials are about the mean of the whole session, not of the tests fitted.
  JointFitOptions o = options;
  o.effects = centred_on(options.effects, session.samples);
  return identify_joint(ballbar_arrays(session, options.tests, with_motion), o);
}

namespace {

// The set-up change that would show what this plan cannot see (issue 13: observability per
// machine), from the names in the unobservable combinations.
std::vector<std::string> setup_advice(MachineType m, const std::vector<std::string>& unobservable) {
  std::vector<std::string> out;
  auto mentions = [&](const std::string& name) {
    for (const std::string& u : unobservable)
      if (u.find(name) != std::string::npos) return true;
    return false;
  };
  if (mentions("tool_offset_Z"))
    out.push_back(
        "pivot_length + tool_length is seen together with the head axis' position along the "
        "spindle: a second tool length (a second ball position along the spindle) in the "
        "head tests separates them");
  const auto& names = location_error_names(m);
  for (int k = 0; k < 2; ++k) {
    const RotaryAxis& a = m.description().axis(k);
    const bool pos = mentions(names[4 * k]) || mentions(names[4 * k + 1]);
    const bool tilt = mentions(names[4 * k + 2]) || mentions(names[4 * k + 3]);
    if (pos && tilt)
      out.push_back(
          std::string("the position and the tilt of ") + a.name +
          " are seen as one combination at the ball's height: a test of " + a.name +
          (a.on_head
               ? " with the ball at a second height (another tool length, or the tilt axis turned: "
                 "axial_c_tilt_deg)"
               : " with the pivot at a second height") +
          " separates them");
  }
  return out;
}

}  // namespace

BallbarIdentification identify_joint(const BallbarArrays& data, const JointFitOptions& options) {
  const BallbarFitSetup setup = ballbar_fit_setup(data, options);
  const BallbarLengthModel model(data, setup.effects);

  // The noise model of what the fit leaves, one AR stream per test in time order; with
  // correlated noise the fit is redone by GLS under it (core/fit_with_noise.hpp).
  const bool streams = static_cast<std::size_t>(data.size()) == data.test.size();
  const std::vector<double> t(data.time.data(), data.time.data() + data.time.size());
  NoiseFit nf = fit_with_noise(
      [&](const JointFitSettings& s) {
        return solve_with_time_constants(model, setup.parameters, s);
      },
      setup.settings, streams ? data.test : std::vector<std::string>{}, t, options.noise);
  const std::string gls_note = noise_refit_note(nf);
  const Eigen::VectorXd values = nf.fit.values;
  BallbarIdentification out;
  static_cast<Identification&>(out) =
      joint_identification(std::move(nf), setup.layout.all, options.whitener != nullptr);
  out.model = ballbar_model_at(setup, data.machine, values);
  out.n_samples = static_cast<std::size_t>(data.size());
  // One residual per sample of the session, 0 for the samples not fitted.
  std::vector<double> fitted(data.session_size, 0.0);
  for (std::size_t k = 0; k < data.index.size(); ++k) fitted[data.index[k]] = out.residuals[k];
  out.residuals = std::move(fitted);
  for (std::string& advice : setup_advice(data.machine, out.unobservable))
    out.notes.push_back(std::move(advice));
  if (!gls_note.empty()) out.notes.push_back(gls_note);
  if (!out.converged) out.notes.push_back("the fit did not converge: " + out.summary.message);
  return out;
}

}  // namespace rotacal
