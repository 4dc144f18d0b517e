// SPDX-License-Identifier: BSD-3-Clause
// Prediction of R-test readings from a model, with their 1 sigma.
#include "rotacal/rtest/predict.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "rotacal/core/error.hpp"

namespace rotacal {

RtestJointModel make_rtest_joint_model(MachineType machine, const RtestBasis& basis_in,
                                       const Eigen::VectorXd& params,
                                       const Eigen::MatrixXd& covariance,
                                       const std::vector<bool>& observable) {
  const RtestBasis basis = basis_in.for_machine(machine);  // head axes' maps have no rotations
  if (basis.b_degree < 0 || basis.c_harmonics < 0 || basis.c_b_degree < 0)
    throw InvalidArgument("R-test joint model: basis: degrees and harmonics must be >= 0");
  const int nl = rtest_num_location_parameters(machine);
  const Eigen::Index n = nl + basis.num_b_coefficients() + basis.num_c_coefficients();
  if (params.size() != n)
    throw InvalidArgument("R-test joint model: params: " + std::to_string(params.size()) +
                          " values, the basis needs " + std::to_string(n) + " (8 location errors" +
                          (nl > 8 ? ", tool_offset_Z" : "") + " + map coefficients)");
  if (covariance.rows() != n || covariance.cols() != n)
    throw InvalidArgument("R-test joint model: covariance: " + std::to_string(covariance.rows()) +
                          " x " + std::to_string(covariance.cols()) + ", expected " +
                          std::to_string(n) + " x " + std::to_string(n));
  if (static_cast<Eigen::Index>(observable.size()) != n)
    throw InvalidArgument("R-test joint model: observable: " + std::to_string(observable.size()) +
                          " flags, expected " + std::to_string(n));
  RtestJointModel named;
  named.machine = machine;
  named.basis = basis;
  const std::vector<std::string> names = named.parameter_names();
  const auto name_of = [&](Eigen::Index j) { return names[static_cast<std::size_t>(j)]; };
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!std::isfinite(params[j]))
      throw InvalidArgument("R-test joint model: params: " + name_of(j) + " is not finite");
    if (!covariance.row(j).allFinite())
      throw InvalidArgument("R-test joint model: covariance: row of " + name_of(j) +
                            " is not finite");
  }
  RtestJointModel m;
  m.machine = machine;
  m.basis = basis;
  m.params = params;
  m.covariance = covariance;
  m.observable = observable;
  return m;
}

RtestSession predict_session(const RtestJointModel& model, const RtestSession& session,
                             const std::map<std::string, Eigen::Vector3d>& probe_zeros) {
  if (session.machine != model.machine)
    throw InvalidArgument("predict_session: the session is a " + to_string(session.machine) +
                          ", the model a " + to_string(model.machine));
  const std::vector<std::string>& std_cols = rtest_prediction_std_columns();
  RtestSession out = session;
  // Column index of each std column in the extra columns (appended when absent).
  std::vector<std::size_t> col;
  for (const std::string& c : std_cols) {
    const auto it = std::find(out.extra_columns.begin(), out.extra_columns.end(), c);
    col.push_back(static_cast<std::size_t>(it - out.extra_columns.begin()));
    if (it == out.extra_columns.end()) out.extra_columns.push_back(c);
  }
  for (std::size_t i = 0; i < out.samples.size(); ++i) {
    RtestSample& s = out.samples[i];
    const auto nest = session.nests.find(s.setup);
    if (nest == session.nests.end())
      throw InvalidArgument("predict_session: session.nests: sample " + std::to_string(i) +
                            " is of set-up '" + s.setup + "', which has no nest");
    Eigen::Vector3d zero = Eigen::Vector3d::Zero();
    if (!probe_zeros.empty()) {
      const auto z = probe_zeros.find(s.setup);
      if (z == probe_zeros.end())
        throw InvalidArgument("predict_session: probe_zeros: no probe zero for set-up '" + s.setup +
                              "'");
      zero = z->second;
    }
    const RotaryAngles<double> a = s.angles_rad();
    Eigen::Vector3d sd;
    s.d = model.reading(nest->second, a.tilt, a.rot, &sd) + zero;
    s.raw.reset();
    s.extra.resize(out.extra_columns.size());
    for (int k = 0; k < 3; ++k) {
      char buf[40] = "";
      if (std::isfinite(sd[k])) std::snprintf(buf, sizeof buf, "%.6g", sd[k]);
      s.extra[col[static_cast<std::size_t>(k)]] = buf;
    }
  }
  const std::string what = std::string("dx,dy,dz predicted by an R-test joint model (") +
                           (probe_zeros.empty() ? "no probe zero" : "fitted probe zeros") +
                           "); dx_std,dy_std,dz_std: 1 sigma, mm";
  auto it = std::find_if(out.metadata.begin(), out.metadata.end(),
                         [](const auto& kv) { return kv.first == "prediction"; });
  if (it != out.metadata.end())
    it->second = what;
  else
    out.metadata.emplace_back("prediction", what);
  return out;
}

}  // namespace rotacal
