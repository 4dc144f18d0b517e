// SPDX-License-Identifier: BSD-3-Clause
// Tests of rtest/model_document.hpp: a joint R-test identification taken apart into its model
// file's content (the file's layout itself: test_io_model_file.cpp).
#include <catch2/catch.hpp>

#include "rotacal/core/error.hpp"
#include "rotacal/rtest/model_document.hpp"

using namespace rotacal;

namespace {

// An identification as identify_rtest_joint reports one: the model's parameters in its order,
// then the probe zeros, in `parameters`; the model's covariance in model order.
RtestJointIdentification sample_identification() {
  RtestJointIdentification r;
  r.model.machine = MachineType::BC_trt;
  r.model.basis.b_degree = 2;
  r.model.basis.c_harmonics = 1;
  r.model.basis.c_b_degree = 0;
  r.model.basis = r.model.basis.for_machine(r.model.machine);
  const std::vector<std::string> names = r.model.parameter_names();
  const auto n = static_cast<Eigen::Index>(names.size());
  r.model.params = Eigen::VectorXd::LinSpaced(n, -1e-3, 2e-3);
  r.model.covariance = Eigen::MatrixXd::Identity(n, n) * 1e-8;
  r.model.observable.assign(names.size(), true);
  for (std::size_t i = 0; i < names.size(); ++i)
    r.parameters.push_back({names[i], r.model.params[static_cast<Eigen::Index>(i)], 1e-4,
                            i < 8 && i % 2 ? "rad" : "mm", i != 5});
  r.probe_zeros["1"] = Eigen::Vector3d(0.001, 0.002, 0.003);
  for (const char* a : {"x", "y", "z"})
    r.parameters.push_back({std::string("zero.1.") + a, 0.002, 1e-4, "mm", true});
  r.residual_rms_um = 1.25;
  r.n_samples = 96;
  r.converged = true;
  r.notes = {"n"};
  return r;
}

}  // namespace

TEST_CASE("the content of a joint identification is its model's parameters in model order") {
  const RtestJointIdentification r = sample_identification();
  const std::map<std::string, Eigen::Vector3d> nests = {{"1", Eigen::Vector3d(100, 0, 50)}};
  const RtestJointModelContent c = rtest_joint_model_content(r, nests);
  CHECK(c.machine == MachineType::BC_trt);
  CHECK(c.b_degree == 2);
  CHECK(c.c_harmonics == 1);
  CHECK(c.c_b_degree == 0);
  const std::vector<std::string> names = r.model.parameter_names();
  REQUIRE(c.parameters.size() == names.size());  // the probe zeros are not model parameters
  for (std::size_t i = 0; i < names.size(); ++i) {
    CHECK(c.parameters[i].name == names[i]);
    CHECK(c.parameters[i].value == r.parameters[i].value);
    CHECK(c.parameters[i].observable == (i != 5));
  }
  CHECK(c.covariance == r.model.covariance);
  CHECK(c.nests == nests);
  REQUIRE(c.probe_zeros.count("1"));
  CHECK(c.probe_zeros.at("1")[2].name == "zero.1.z");
  CHECK(c.n_samples == 96);
  CHECK(c.notes == r.notes);
  // The document of the identification is the document of its content.
  CHECK(rtest_joint_model_document(r, nests) == rtest_joint_model_document(c));
}

TEST_CASE("an identification without one of its model's parameters is refused by name") {
  RtestJointIdentification r = sample_identification();
  r.parameters.erase(r.parameters.begin() + 2);
  CHECK_THROWS_AS(rtest_joint_model_content(r, {}), InvalidArgument);
  r = sample_identification();
  r.parameters.pop_back();  // zero.1.z
  CHECK_THROWS_WITH(rtest_joint_model_content(r, {}), Catch::Contains("zero.1.z"));
}
