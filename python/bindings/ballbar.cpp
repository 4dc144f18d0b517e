// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/ballbar (model, simulation, joint fit, compensation).
#include "numpy.hpp"
#include "rotacal/ballbar/compensate.hpp"
#include "rotacal/ballbar/identify.hpp"
#include "rotacal/ballbar/identify_paper.hpp"
#include "rotacal/ballbar/monte_carlo.hpp"
#include "rotacal/ballbar/simulate.hpp"

namespace rotacal::py {

namespace {

// Parameter estimates, fit summaries, the machine model and the identification.
void bind_ballbar_results(pyb::module_& m) {
  pyb::class_<ParameterEstimate>(m, "ParameterEstimate")
      .def_readonly("name", &ParameterEstimate::name)
      .def_readonly("value", &ParameterEstimate::value)
      .def_readonly("std", &ParameterEstimate::std)
      .def_readonly("unit", &ParameterEstimate::unit)
      .def_readonly("observable", &ParameterEstimate::observable)
      .def("__repr__", [](const ParameterEstimate& p) {
        return "ParameterEstimate(" + p.name + "=" + std::to_string(p.value) + " +- " +
               std::to_string(p.std) + " " + p.unit + (p.observable ? "" : ", unobservable") + ")";
      });

  pyb::class_<FitSummary>(m, "FitSummary", "How a least-squares solve went (core/estimate.hpp).")
      .def_readonly("converged", &FitSummary::converged)
      .def_readonly("iterations", &FitSummary::iterations)
      .def_readonly("jacobian_evaluations", &FitSummary::jacobian_evaluations)
      .def_readonly("residual_evaluations", &FitSummary::residual_evaluations)
      .def_readonly("num_residuals", &FitSummary::num_residuals)
      .def_readonly("num_free", &FitSummary::num_free)
      .def_readonly("chi2", &FitSummary::chi2)
      .def_readonly("chi2_per_dof", &FitSummary::chi2_per_dof)
      .def_readonly("whitened", &FitSummary::whitened)
      .def_readonly("message", &FitSummary::message);

  pyb::class_<Identification>(
      m, "Identification",
      "What an identification reports, whatever the instrument (core/identification.hpp); "
      "the instrument's parts (pivot, zeros, sphere, effects) are named blocks of `parameters`.")
      .def_readonly("method", &Identification::method)
      .def_readonly("parameters", &Identification::parameters)
      .def_property_readonly("block_names",
                             [](const Identification& r) {
                               std::vector<std::string> out;
                               for (const ParameterBlock& b : r.blocks.blocks())
                                 out.push_back(b.name);
                               return out;
                             })
      .def("block", &Identification::block, pyb::arg("name"),
           "The estimates of the named parameter block (e.g. 'pivot', 'sphere', 'zeros').")
      .def("parameter", &Identification::parameter, pyb::arg("name"),
           pyb::return_value_policy::copy, "The estimate called `name`.")
      .def_readonly("covariance", &Identification::covariance)
      .def_property_readonly(
          "residuals",
          [](const Identification& r) {
            return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
                r.residuals.data(), static_cast<Eigen::Index>(r.residuals.size())));
          })
      .def_readonly("residual_rms_um", &Identification::residual_rms_um)
      .def_readonly("sigma_um", &Identification::sigma_um)
      .def_readonly("n_samples", &Identification::n_samples)
      .def_readonly("converged", &Identification::converged)
      .def_readonly("iterations", &Identification::iterations)
      .def_readonly("unobservable", &Identification::unobservable)
      .def_readonly("notes", &Identification::notes)
      .def_readonly("summary", &Identification::summary)
      .def_readonly("noise", &Identification::noise)
      .def_readonly("noise_refit", &Identification::noise_refit)
      .def_readonly("noise_correction", &Identification::noise_correction);

  pyb::class_<BallbarMachineModel>(m, "BallbarMachineModel",
                                   "Location errors, actual pivot and effects of a machine.")
      .def(pyb::init(
               [](MachineType machine,
                  const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& errors,
                  const pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>& pivot,
                  const std::vector<std::string>& effects,
                  const std::vector<double>& effect_params) {
                 BallbarMachineModel b;
                 b.machine = machine;
                 b.errors = LocationErrors<double>(vec_of<8>(errors, "errors"));
                 b.pivot = vec_of<3>(pivot, "pivot");
                 b.effects = effects_of(effects);
                 b.effect_params = effect_params;
                 if (static_cast<int>(b.effect_params.size()) != b.effects.num_params())
                   throw InvalidArgument("effect_params: expected " +
                                         std::to_string(b.effects.num_params()) + " values");
                 return b;
               }),
           pyb::arg("machine"), pyb::arg("errors"), pyb::arg("pivot"),
           pyb::arg("effects") = std::vector<std::string>{},
           pyb::arg("effect_params") = std::vector<double>{})
      .def_readonly("machine", &BallbarMachineModel::machine)
      .def_property_readonly(
          "errors", [](const BallbarMachineModel& b) { return Eigen::VectorXd(b.errors.v); })
      .def_property_readonly("pivot",
                             [](const BallbarMachineModel& b) { return Eigen::Vector3d(b.pivot); })
      .def_property_readonly("effects",
                             [](const BallbarMachineModel& b) { return ids_of(b.effects); })
      .def_readonly("effect_params", &BallbarMachineModel::effect_params);

  pyb::class_<BallbarIdentification, Identification>(m, "BallbarIdentification")
      .def_readonly("model", &BallbarIdentification::model);
}

// The joint fit, its Monte Carlo check and the paper's method.
void bind_ballbar_identification(pyb::module_& m) {
  m.def(
      "identify_joint",
      [](const BallbarSession& session, bool fit_length_offset,
         const std::vector<std::string>& effects, const std::vector<std::string>& tests,
         const std::string& noise) {
        JointFitOptions o;
        o.fit_length_offset = fit_length_offset;
        o.effects = effects_of(effects);
        o.tests = tests;
        o.noise.noise = noise_handling_from_string(noise);
        pyb::gil_scoped_release release;
        return identify_joint(session, o);
      },
      pyb::arg("session"), pyb::arg("fit_length_offset") = false,
      pyb::arg("effects") = std::vector<std::string>{},
      pyb::arg("tests") = std::vector<std::string>{}, pyb::arg("noise") = "auto",
      "Joint fit (noise 'auto': AR noise model of the residuals, GLS refit when correlated; "
      "'white') of the 8 location errors and the actual pivot to every sample "
      "(core/joint_fit.hpp).");

  pyb::class_<MonteCarloParameter>(m, "MonteCarloParameter")
      .def_readonly("name", &MonteCarloParameter::name)
      .def_readonly("unit", &MonteCarloParameter::unit)
      .def_readonly("std_reported", &MonteCarloParameter::std_reported)
      .def_readonly("std_mc", &MonteCarloParameter::std_mc)
      .def_readonly("ratio", &MonteCarloParameter::ratio)
      .def_readonly("bias", &MonteCarloParameter::bias);
  pyb::class_<BallbarMonteCarlo>(m, "BallbarMonteCarlo")
      .def_readonly("draws", &BallbarMonteCarlo::draws)
      .def_readonly("noise_um", &BallbarMonteCarlo::noise_um)
      .def_readonly("noise", &BallbarMonteCarlo::noise)
      .def_readonly("parameters", &BallbarMonteCarlo::parameters)
      .def_readonly("values", &BallbarMonteCarlo::values)
      .def_readonly("fresh_fits", &BallbarMonteCarlo::fresh_fits);
  m.def(
      "monte_carlo_joint",
      [](const BallbarSession& session, const BallbarIdentification& result, int draws,
         std::uint64_t seed, double noise_um, const std::vector<std::string>& tests,
         const pyb::object& progress) {
        BallbarMonteCarloOptions o;
        o.draws = draws;
        o.seed = seed;
        o.noise_um = noise_um;
        o.fit.tests = tests;
        o.progress = progress_callback(progress);
        pyb::gil_scoped_release release;
        return monte_carlo(session, result, o);
      },
      pyb::arg("session"), pyb::arg("result"), pyb::arg("draws") = 100, pyb::arg("seed") = 1,
      pyb::arg("noise_um") = 0.0, pyb::arg("tests") = std::vector<std::string>{},
      pyb::arg("progress") = pyb::none(),
      R"doc(Monte Carlo check of a joint fit's 1-sigma (ballbar/monte_carlo.hpp).

Parameters
----------
session : the session that was identified
result : its joint identification
draws : number of simulated sessions (>= 2); draw k uses seed + k, as simulate_ballbar
noise_um : 1 sigma of the simulated noise (0: the fit's sigma_um)
tests : the test labels the fit used (empty: all)
progress : optional callable(done, total), called after every draw

Returns
-------
BallbarMonteCarlo: per observable parameter std_reported, std_mc, ratio, bias; values
(draws x parameters).)doc");

  m.def(
      "identify_paper",
      [](const BallbarSession& session) {
        pyb::gil_scoped_release release;
        return identify_paper(session);
      },
      pyb::arg("session"),
      "Flynn et al. 2016's chain: sphere fit, Hyper circle fits, SVD plane fits, transport.");
}

// Simulation, predicted lengths and compensation.
void bind_ballbar_simulation(pyb::module_& m) {
  m.def(
      "simulate_ballbar",
      [](const BallbarSession& commanded, const BallbarMachineModel& truth, double noise_um,
         std::uint64_t seed, bool declare_noise) {
        return simulate_ballbar(commanded, truth, {noise_um, seed, declare_noise});
      },
      pyb::arg("commanded"), pyb::arg("truth"), pyb::arg("noise_um") = 0.5, pyb::arg("seed") = 1,
      pyb::arg("declare_noise") = true,
      "The session as the machine `truth` would measure it (lengths filled in, Gaussian noise).");

  m.def(
      "predict_session_lengths",
      [](const BallbarMachineModel& model, const BallbarSession& s) {
        const std::vector<double> L = predict_lengths(model, s.samples);
        return Eigen::VectorXd(
            Eigen::Map<const Eigen::VectorXd>(L.data(), static_cast<Eigen::Index>(L.size())));
      },
      pyb::arg("model"), pyb::arg("session"),
      "Predicted centre-to-centre lengths (mm) of every sample of the session on the model.");

  m.def(
      "compensate_commands", &compensate_commands, pyb::arg("nominal"), pyb::arg("identified"),
      pyb::arg("machine"), pyb::arg("tool_length_error") = 0.0,
      "Compensated commands; tool_length_error (mm): the error of pivot_length + tool_length of a "
      "head machine (minus the identified tool_offset_Z).");

  pyb::class_<CompensationRow>(m, "CompensationRow")
      .def_readonly("name", &CompensationRow::name)
      .def_readonly("unit", &CompensationRow::unit)
      .def_readonly("before", &CompensationRow::before)
      .def_readonly("after", &CompensationRow::after)
      .def_readonly("std_after", &CompensationRow::std_after)
      .def_readonly("change_percent", &CompensationRow::change_percent);
  pyb::class_<CompensationReport>(m, "CompensationReport")
      .def_readonly("rows", &CompensationReport::rows)
      .def_readonly("before", &CompensationReport::before)
      .def_readonly("after", &CompensationReport::after);
  m.def(
      "verify_compensation",
      [](const BallbarSession& commanded, const BallbarMachineModel& truth, double noise_um,
         std::uint64_t seed) {
        pyb::gil_scoped_release release;
        return verify_compensation(commanded, truth, {noise_um, seed, true});
      },
      pyb::arg("commanded"), pyb::arg("truth"), pyb::arg("noise_um") = 0.5, pyb::arg("seed") = 1,
      "Measure, identify, compensate, measure again, identify again (Flynn et al., Table 2).");
}

}  // namespace

void bind_ballbar(pyb::module_& m) {
  bind_ballbar_results(m);
  bind_ballbar_identification(m);
  bind_ballbar_simulation(m);
}

}  // namespace rotacal::py
