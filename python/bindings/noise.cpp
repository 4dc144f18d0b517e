// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/core/noise_model.hpp and diagnose/uncertainty_budget.hpp.
#include "numpy.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/diagnose/ballbar_diagnosis.hpp"
#include "rotacal/diagnose/rtest_budget.hpp"
#include "rotacal/diagnose/rtest_diagnosis.hpp"
#include "rotacal/diagnose/uncertainty_budget.hpp"

namespace rotacal::py {

void bind_noise(pyb::module_& m) {
  pyb::class_<NoiseModelOptions>(m, "NoiseModelOptions")
      .def(pyb::init<>())
      .def_readwrite("max_order", &NoiseModelOptions::max_order)
      .def_readwrite("min_stream_size", &NoiseModelOptions::min_stream_size)
      .def_readwrite("pooled", &NoiseModelOptions::pooled);

  pyb::class_<NoiseStream>(m, "NoiseStream")
      .def_readonly("group", &NoiseStream::group)
      .def_readonly("channel", &NoiseStream::channel)
      .def_readonly("ar", &NoiseStream::ar)
      .def_readonly("reflection", &NoiseStream::reflection)
      .def_readonly("innovation_sigma_um", &NoiseStream::innovation_sigma_um)
      .def_readonly("marginal_sigma_um", &NoiseStream::marginal_sigma_um)
      .def_readonly("correlation_samples", &NoiseStream::correlation_samples)
      .def_readonly("sample_interval_s", &NoiseStream::sample_interval_s)
      .def_readonly("correlation_time_s", &NoiseStream::correlation_time_s)
      .def_readonly("effective_samples", &NoiseStream::effective_samples)
      .def_readonly("random_walk_step_um", &NoiseStream::random_walk_step_um,
                    "1 sigma of the random-walk step per reading, um (0: none; R-test REML)")
      .def_property_readonly("n", [](const NoiseStream& s) { return s.rows.size(); });

  pyb::class_<NoiseModel>(m, "NoiseModel")
      .def_readonly("streams", &NoiseModel::streams)
      .def_readonly("n", &NoiseModel::n)
      .def_readonly("sigma_um", &NoiseModel::sigma_um)
      .def_readonly("innovation_sigma_um", &NoiseModel::innovation_sigma_um)
      .def_readonly("correlation_samples", &NoiseModel::correlation_samples)
      .def_readonly("correlation_time_s", &NoiseModel::correlation_time_s)
      .def_readonly("effective_samples", &NoiseModel::effective_samples)
      .def_readonly("max_order", &NoiseModel::max_order)
      .def_readonly("random_walk_step_um", &NoiseModel::random_walk_step_um,
                    "largest random-walk step of any stream, um (0: none)")
      .def_property_readonly("white", &NoiseModel::white)
      .def("summary", &NoiseModel::summary)
      .def(
          "whiten",
          [](const NoiseModel& model, const Eigen::MatrixXd& columns, double residual_unit_mm) {
            Eigen::MatrixXd out = columns;
            ArWhitener(model, residual_unit_mm).apply(out);
            return out;
          },
          pyb::arg("columns"), pyb::arg("residual_unit_mm") = 1.0,
          "Whitened copy of `columns` (one row per reading): unit variance if the model holds.");

  m.def(
      "estimate_noise_model",
      [](const std::vector<std::string>& groups, const std::vector<double>& times,
         const Eigen::VectorXd& residuals_mm, const NoiseModelOptions& options) {
        pyb::gil_scoped_release release;
        return estimate_noise_model(groups, times, residuals_mm, options);
      },
      pyb::arg("groups"), pyb::arg("times"), pyb::arg("residuals_mm"),
      pyb::arg("options") = NoiseModelOptions{},
      "AR(p) model (Burg, BIC order) of the residuals per stream (group, channel).");
  m.def("noise_ar1", &noise_gen::ar1, pyb::arg("groups"), pyb::arg("times"), pyb::arg("rho"),
        pyb::arg("sigma_mm"), pyb::arg("seed"));
  m.def("noise_pink", &noise_gen::pink, pyb::arg("groups"), pyb::arg("times"), pyb::arg("sigma_mm"),
        pyb::arg("seed"));
  m.def("noise_thermal_wander", &noise_gen::thermal_wander, pyb::arg("times"),
        pyb::arg("amplitude_mm"), pyb::arg("period_s"), pyb::arg("seed"));
  m.def("noise_probe_zero_wander", &noise_gen::probe_zero_wander, pyb::arg("groups"),
        pyb::arg("times"), pyb::arg("step_mm"), pyb::arg("seed"));

  pyb::class_<PlausibleSizes>(m, "PlausibleSizes")
      .def(pyb::init<>())
      .def_readwrite("squareness_rad", &PlausibleSizes::squareness_rad)
      .def_readwrite("straightness_mm", &PlausibleSizes::straightness_mm)
      .def_readwrite("straightness_length_mm", &PlausibleSizes::straightness_length_mm)
      .def_readwrite("drift_mm", &PlausibleSizes::drift_mm)
      .def_readwrite("warmup_mm", &PlausibleSizes::warmup_mm)
      .def_readwrite("tool_length_mm", &PlausibleSizes::tool_length_mm)
      .def_readwrite("tool_offset_mm", &PlausibleSizes::tool_offset_mm)
      .def_readwrite("bar_length_mm", &PlausibleSizes::bar_length_mm)
      .def_readwrite("scale", &PlausibleSizes::scale)
      .def_readwrite("angular_error_rad", &PlausibleSizes::angular_error_rad)
      .def_readwrite("rotary_zero_rad", &PlausibleSizes::rotary_zero_rad)
      .def_readwrite("angular_positioning_rad", &PlausibleSizes::angular_positioning_rad)
      .def_readwrite("error_motion_mm", &PlausibleSizes::error_motion_mm)
      .def_readwrite("tilt_motion_rad", &PlausibleSizes::tilt_motion_rad)
      .def_readwrite("gravity_sag_mm", &PlausibleSizes::gravity_sag_mm)
      .def_readwrite("coning", &PlausibleSizes::coning)
      .def_readwrite("backlash_rad", &PlausibleSizes::backlash_rad)
      .def_readwrite("servo_lag_s", &PlausibleSizes::servo_lag_s)
      .def_readwrite("reversal_spike_rad", &PlausibleSizes::reversal_spike_rad)
      .def_readwrite("stylus_radius_mm", &PlausibleSizes::stylus_radius_mm)
      .def_readwrite("probe_lobing_mm", &PlausibleSizes::probe_lobing_mm)
      .def_readwrite("overrides", &PlausibleSizes::overrides)
      .def_readwrite("use_session_bounds", &PlausibleSizes::use_session_bounds);

  pyb::class_<BudgetLine>(m, "BudgetLine")
      .def_readonly("effect", &BudgetLine::effect)
      .def_readonly("basis", &BudgetLine::basis)
      .def_readonly("u", &BudgetLine::u)
      .def_readonly("bias_at_size", &BudgetLine::bias_at_size)
      .def_readonly("dof", &BudgetLine::dof)
      .def_readonly("half_width", &BudgetLine::half_width);

  pyb::class_<LocationBudget>(m, "LocationBudget")
      .def_readonly("name", &LocationBudget::name)
      .def_readonly("unit", &LocationBudget::unit)
      .def_readonly("observable", &LocationBudget::observable)
      .def_readonly("value", &LocationBudget::value)
      .def_readonly("u_a", &LocationBudget::u_a)
      .def_readonly("dof_a", &LocationBudget::dof_a)
      .def_readonly("type_b", &LocationBudget::type_b)
      .def_readonly("u_c", &LocationBudget::u_c)
      .def_readonly("nu_eff", &LocationBudget::nu_eff)
      .def_readonly("k", &LocationBudget::k)
      .def_readonly("expanded", &LocationBudget::expanded)
      .def_readonly("dominant", &LocationBudget::dominant);

  pyb::class_<UncertaintyBudget>(m, "UncertaintyBudget")
      .def_readonly("coverage", &UncertaintyBudget::coverage)
      .def_readonly("errors", &UncertaintyBudget::errors);

  m.def(
      "uncertainty_budget_ballbar",
      [](const BallbarSession& session, const Diagnosis& diagnosis, const PlausibleSizes& sizes,
         double coverage) {
        pyb::gil_scoped_release release;
        return uncertainty_budget(BallbarDiagnosisProblem(session), diagnosis, sizes, coverage);
      },
      pyb::arg("session"), pyb::arg("diagnosis"), pyb::arg("sizes") = PlausibleSizes{},
      pyb::arg("coverage") = 0.95,
      "GUM budget of the location errors of diagnose_ballbar's result.");
  m.def(
      "uncertainty_budget_rtest",
      [](const RtestSession& session, const Diagnosis& diagnosis, const PlausibleSizes& sizes,
         double coverage) {
        pyb::gil_scoped_release release;
        return uncertainty_budget(RtestDiagnosisProblem(session), diagnosis, sizes, coverage);
      },
      pyb::arg("session"), pyb::arg("diagnosis"), pyb::arg("sizes") = PlausibleSizes{},
      pyb::arg("coverage") = 0.95, "GUM budget of the location errors of diagnose_rtest's result.");
  m.def(
      "uncertainty_budget_rtest_identification",
      [](const RtestSession& session, const RtestJointIdentification& identification,
         const PlausibleSizes& sizes, double coverage) {
        pyb::gil_scoped_release release;
        return uncertainty_budget(session, identification, sizes, coverage);
      },
      pyb::arg("session"), pyb::arg("identification"), pyb::arg("sizes") = PlausibleSizes{},
      pyb::arg("coverage") = 0.95,
      "GUM budget of the location errors of identify_rtest_joint's result, on its own model (maps "
      "included).");
}

}  // namespace rotacal::py
