// SPDX-License-Identifier: BSD-3-Clause
// Each instrument's problem as one session of the stacked fit (src/multi/session_parts.hpp).
// Only this layer includes the three instrument problems; they do not include each other.
#include "session_parts.hpp"

#include <algorithm>

#include "../ballbar/length_model.hpp"
#include "rotacal/ballbar/problem.hpp"
#include "rotacal/kinematics/parameter_blocks.hpp"
#include "rotacal/probe/problem.hpp"
#include "rotacal/probe/touch_noise.hpp"
#include "rotacal/rtest/problem.hpp"
#include "rotacal/session/probe_session.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal::multi_detail {
namespace {

// The arrays and the fit set-up a BallbarLengthModel refers to.
struct BallbarData {
  BallbarArrays arrays;
  BallbarFitSetup setup;
};

SessionPart ballbar_part(const MultiSessionInput& in, const EffectModel& fx) {
  SessionPart p;
  auto data = std::make_shared<BallbarData>();
  data->arrays = ballbar_arrays(*in.ballbar);
  JointFitOptions options;
  options.effects = fx;
  data->setup = ballbar_fit_setup(data->arrays, options);
  const BallbarArrays* arrays = &data->arrays;
  const BallbarFitSetup& setup = data->setup;
  p.model = std::make_unique<BallbarLengthModel>(*arrays, setup.effects);
  p.parameters = setup.parameters;
  p.errors_offset = setup.layout.errors.offset;
  p.errors_size = setup.layout.errors.size;
  p.settings = setup.settings;
  if (static_cast<std::size_t>(arrays->size()) == arrays->test.size()) p.groups = arrays->test;
  p.times.assign(arrays->time.data(), arrays->time.data() + arrays->time.size());
  p.data = data;
  return p;
}

SessionPart rtest_part(const MultiSessionInput& in, const EffectModel& fx) {
  SessionPart p;
  auto arrays = std::make_shared<RtestArrays>(rtest_arrays(*in.rtest, "identify: " + in.name));
  auto problem = std::make_unique<RtestProblem>(*arrays, nullptr, fx);
  const RtestLayout& L = problem->layout();
  const std::vector<std::string> names = L.all.names(), units = L.all.units();
  for (std::size_t j = 0; j < names.size(); ++j) p.parameters.push_back({names[j], units[j], 0.0});
  // Each probe zero starts at its set-up's mean reading (the answer for zero errors).
  Eigen::Matrix3Xd sum = Eigen::Matrix3Xd::Zero(3, L.zeros.items());
  Eigen::VectorXd count = Eigen::VectorXd::Zero(L.zeros.items());
  for (Eigen::Index i = 0; i < arrays->size(); ++i) {
    const int k = arrays->setup_of[static_cast<std::size_t>(i)];
    sum.col(k) += arrays->d.col(i);
    count[k] += 1.0;
  }
  for (Eigen::Index k = 0; k < L.zeros.items(); ++k)
    for (int a = 0; a < 3; ++a)
      p.parameters[static_cast<std::size_t>(L.zeros.item_offset(k) + a)].start =
          sum(a, k) / count[k];
  p.errors_offset = L.errors.offset;
  p.errors_size = L.errors.size;
  p.settings.sigma = in.rtest->noise_um.value_or(1.0) * 1e-3;
  // Noise streams as the R-test's own fit has them: one per nest and channel, in time order.
  for (std::size_t i = 0; i < arrays->setup_of.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      p.groups.push_back("nest " + arrays->setups[static_cast<std::size_t>(arrays->setup_of[i])]);
      p.times.push_back(arrays->time[i]);
    }
  p.allow_reml = true;
  p.model = std::move(problem);
  p.data = arrays;
  return p;
}

SessionPart probe_part(const MultiSessionInput& in, const EffectModel& fx) {
  SessionPart p;
  auto problem = std::make_unique<ProbeProblem>(*in.probe, fx);
  p.parameters = problem->parameters();
  p.errors_offset = static_cast<Eigen::Index>(problem->layout().errors.offset);
  p.errors_size = static_cast<Eigen::Index>(problem->layout().errors.size);
  p.settings.sigma = in.probe->noise_um.value_or(1.0) * 1e-3;
  p.groups = problem->groups();
  p.times = problem->times();
  p.own_noise = touch_noise_model(in.probe);
  p.model = std::move(problem);
  p.data = in.probe;
  return p;
}

}  // namespace

SessionPart session_part(const MultiSessionInput& in, const EffectModel& fx) {
  SessionPart p;
  if (in.instrument == "ballbar" && in.ballbar)
    p = ballbar_part(in, fx);
  else if (in.instrument == "rtest" && in.rtest)
    p = rtest_part(in, fx);
  else if (in.instrument == "probe" && in.probe)
    p = probe_part(in, fx);
  else
    throw InvalidArgument("identify: session " + in.name + " has no " + in.instrument + " data");
  p.name = in.name;
  p.instrument = in.instrument;
  if (p.model->num_residuals() <= static_cast<Eigen::Index>(p.parameters.size()))
    throw InvalidArgument(
        "identify: session " + in.name + ": " + std::to_string(p.model->num_residuals()) +
        " residuals cannot determine its " + std::to_string(p.parameters.size()) + " unknowns");
  std::vector<std::string> shared_names;
  for (Eigen::Index j = 0; j < p.errors_size; ++j)
    shared_names.push_back(p.parameters[static_cast<std::size_t>(p.errors_offset + j)].name);
  for (const Effect& f : fx.effects)
    for (std::size_t k = 0; k < static_cast<std::size_t>(f.num_params()); ++k)
      shared_names.push_back(effect_parameter_name(f, k));
  for (const FitParameter& f : p.parameters) {
    const auto at = std::find(shared_names.begin(), shared_names.end(), f.name);
    p.shared.push_back(
        at == shared_names.end() ? -1 : static_cast<Eigen::Index>(at - shared_names.begin()));
  }
  return p;
}

}  // namespace rotacal::multi_detail
