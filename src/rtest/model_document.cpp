// SPDX-License-Identifier: BSD-3-Clause
// A joint R-test identification as a model document (rtest/model_document.hpp).
#include "rotacal/rtest/model_document.hpp"

#include "rotacal/core/error.hpp"

namespace rotacal {

RtestJointModelContent rtest_joint_model_content(
    const RtestJointIdentification& ident, const std::map<std::string, Eigen::Vector3d>& nests) {
  std::map<std::string, const ParameterEstimate*> by_name;
  for (const ParameterEstimate& p : ident.parameters) by_name[p.name] = &p;
  const auto find = [&](const std::string& name) -> const ParameterEstimate& {
    const auto it = by_name.find(name);
    if (it == by_name.end())
      throw InvalidArgument("rtest_joint_model_content: the identification has no parameter '" +
                            name + "'");
    return *it->second;
  };
  const RtestJointModel& m = ident.model;
  RtestJointModelContent c;
  c.machine = m.machine;
  c.b_degree = m.basis.b_degree;
  c.c_harmonics = m.basis.c_harmonics;
  c.c_b_degree = m.basis.c_b_degree;
  c.gamma_cb = m.basis.gamma_cb;
  for (const std::string& name : m.parameter_names()) c.parameters.push_back(find(name));
  c.covariance = m.covariance;
  c.nests = nests;
  for (const auto& zero : ident.probe_zeros) {
    const std::string z = "zero." + zero.first + ".";
    c.probe_zeros[zero.first] = {find(z + "x"), find(z + "y"), find(z + "z")};
  }
  c.residual_rms_um = ident.residual_rms_um;
  c.sigma_um = ident.sigma_um;
  c.n_samples = ident.n_samples;
  c.converged = ident.converged;
  c.unobservable = ident.unobservable;
  c.notes = ident.notes;
  return c;
}

nlohmann::ordered_json rtest_joint_model_document(
    const RtestJointIdentification& ident, const std::map<std::string, Eigen::Vector3d>& nests) {
  return rtest_joint_model_document(rtest_joint_model_content(ident, nests));
}

}  // namespace rotacal
