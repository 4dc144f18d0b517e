// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/diagnose.
#include <pybind11/functional.h>

#include "numpy.hpp"
#include "rotacal/diagnose/ballbar_diagnosis.hpp"
#include "rotacal/diagnose/rtest_diagnosis.hpp"

namespace rotacal::py {

namespace {

// The options, fits, gains and findings of a diagnosis.
void bind_diagnosis_findings(pyb::module_& m) {
  pyb::class_<DiagnosisOptions>(m, "DiagnosisOptions")
      .def(pyb::init<>())
      .def_readwrite("max_harmonic", &DiagnosisOptions::max_harmonic)
      .def_readwrite("max_findings", &DiagnosisOptions::max_findings)
      .def_readwrite("alpha", &DiagnosisOptions::alpha)
      .def_readwrite("min_delta_bic", &DiagnosisOptions::min_delta_bic)
      .def_readwrite("cv_blocks", &DiagnosisOptions::cv_blocks)
      .def_readwrite("only", &DiagnosisOptions::only)
      .def_readwrite("hold_by_weight", &DiagnosisOptions::hold_by_weight)
      .def_readwrite("model_noise", &DiagnosisOptions::model_noise)
      .def_readwrite("min_weight", &DiagnosisOptions::min_weight)
      .def_readwrite("rival_correlation", &DiagnosisOptions::rival_correlation)
      .def_readwrite("min_determined_sigma", &DiagnosisOptions::min_determined_sigma)
      .def_readwrite("progress", &DiagnosisOptions::progress,
                     "callable(stage, done, total) after each scored candidate, or None");

  pyb::class_<ModelFit>(m, "ModelFit")
      .def_property_readonly("effects",
                             [](const ModelFit& f) {
                               std::vector<std::string> ids;
                               for (const Effect& e : f.effects.effects) ids.push_back(e.id());
                               return ids;
                             })
      .def_readonly("parameters", &ModelFit::parameters)
      .def_readonly("residuals", &ModelFit::residuals)
      .def_readonly("num_free", &ModelFit::num_free);

  pyb::class_<GroupResidual>(m, "GroupResidual")
      .def_readonly("group", &GroupResidual::group)
      .def_readonly("n", &GroupResidual::n)
      .def_readonly("rms_um", &GroupResidual::rms_um)
      .def_readonly("mean_um", &GroupResidual::mean_um)
      .def_property_readonly("angle_axis",
                             [](const GroupResidual& g) {
                               return g.angle_axis ? std::string(1, g.angle_axis) : std::string();
                             })
      .def_readonly("harmonic_um", &GroupResidual::harmonic_um)
      .def_readonly("harmonics_left_out", &GroupResidual::harmonics_left_out)
      .def_readonly("harmonic_note", &GroupResidual::harmonic_note)
      .def_readonly("trend_um_per_s", &GroupResidual::trend_um_per_s);

  pyb::class_<Gain>(m, "Gain")
      .def_readonly("rms_before_um", &Gain::rms_before_um)
      .def_readonly("rms_after_um", &Gain::rms_after_um)
      .def_readonly("delta_bic", &Gain::delta_bic)
      .def_readonly("cv_rms_before_um", &Gain::cv_rms_before_um)
      .def_readonly("cv_rms_after_um", &Gain::cv_rms_after_um)
      .def_readonly("f_pvalue", &Gain::f_pvalue);

  pyb::class_<Finding::Shift>(m, "ParameterShift")
      .def_readonly("name", &Finding::Shift::name)
      .def_readonly("before", &Finding::Shift::before)
      .def_readonly("after", &Finding::Shift::after)
      .def_readonly("std_after", &Finding::Shift::std_after)
      .def_readonly("unit", &Finding::Shift::unit);

  pyb::class_<Alternative>(m, "Alternative")
      .def_readonly("effect", &Alternative::effect)
      .def_readonly("weight", &Alternative::weight)
      .def_readonly("delta_bic", &Alternative::delta_bic)
      .def_readonly("correlation", &Alternative::correlation)
      .def_readonly("in_group", &Alternative::in_group)
      .def_readonly("aliased", &Alternative::aliased);

  pyb::class_<Finding>(m, "Finding")
      .def_property_readonly("effect", [](const Finding& f) { return f.effect.id(); })
      .def_readonly("model_reason", &Finding::model_reason)
      .def_readonly("cause", &Finding::cause)
      .def_readonly("weight", &Finding::weight)
      .def_readonly("rivals", &Finding::rivals)
      .def_property_readonly("named_alone", &Finding::named_alone)
      .def_readonly("lack_of_fit", &Finding::lack_of_fit)
      .def_readonly("parameters", &Finding::parameters)
      .def_readonly("gain", &Finding::gain)
      .def_readonly("shifts", &Finding::shifts);

  pyb::class_<Ambiguity>(m, "Ambiguity")
      .def_readonly("effects", &Ambiguity::effects)
      .def_readonly("delta_bic", &Ambiguity::delta_bic)
      .def_readonly("correlation", &Ambiguity::correlation)
      .def_readonly("separating_test", &Ambiguity::separating_test);

  pyb::class_<UnobservableEffect>(m, "UnobservableEffect")
      .def_readonly("effect", &UnobservableEffect::effect)
      .def_readonly("reason", &UnobservableEffect::reason);

  pyb::class_<Unexplained>(m, "Unexplained")
      .def_readonly("present", &Unexplained::present)
      .def_readonly("chi2_per_dof", &Unexplained::chi2_per_dof)
      .def_readonly("p_value", &Unexplained::p_value)
      .def_readonly("signature", &Unexplained::signature)
      .def_readonly("group", &Unexplained::group)
      .def_property_readonly(
          "axis",
          [](const Unexplained& u) { return u.axis ? std::string(1, u.axis) : std::string(); })
      .def_readonly("range_from", &Unexplained::range_from)
      .def_readonly("range_to", &Unexplained::range_to)
      .def_readonly("noise_structure", &Unexplained::noise_structure)
      .def_readonly("noise_structure_p", &Unexplained::noise_structure_p)
      .def_readonly("size_um", &Unexplained::size_um)
      .def_readonly("at", &Unexplained::at)
      .def_readonly("noise_um", &Unexplained::noise_um)
      .def_readonly("suggested_test", &Unexplained::suggested_test);
}

// The diagnosis report and the diagnose functions.
void bind_diagnosis_report(pyb::module_& m) {
  pyb::class_<AngleTable>(m, "AngleTable")
      .def_readonly("group", &AngleTable::group)
      .def_property_readonly("axis", [](const AngleTable& t) { return std::string(1, t.axis); })
      .def_readonly("angle_deg", &AngleTable::angle_deg)
      .def_readonly("value_um", &AngleTable::value_um)
      .def_readonly("std_um", &AngleTable::std_um)
      .def_readonly("count", &AngleTable::count)
      .def_readonly("gain", &AngleTable::gain);

  pyb::class_<CandidateScore>(m, "CandidateScore")
      .def_readonly("effect", &CandidateScore::effect)
      .def_readonly("visible_params", &CandidateScore::visible_params)
      .def_readonly("delta_bic", &CandidateScore::delta_bic)
      .def_readonly("f_pvalue", &CandidateScore::f_pvalue)
      .def_readonly("rms_after_um", &CandidateScore::rms_after_um);

  pyb::class_<Diagnosis::Baseline>(m, "DiagnosisBaseline")
      .def_readonly("residual_rms_um", &Diagnosis::Baseline::residual_rms_um)
      .def_readonly("noise_um", &Diagnosis::Baseline::noise_um)
      .def_readonly("noise_source", &Diagnosis::Baseline::noise_source)
      .def_readonly("chi2_per_dof", &Diagnosis::Baseline::chi2_per_dof)
      .def_readonly("p_value", &Diagnosis::Baseline::p_value)
      .def_readonly("n", &Diagnosis::Baseline::n)
      .def_readonly("dof", &Diagnosis::Baseline::dof);

  pyb::class_<Diagnosis>(m, "Diagnosis")
      .def_readonly("machine", &Diagnosis::machine)
      .def_readonly("baseline", &Diagnosis::baseline)
      .def_readonly("structure_before", &Diagnosis::structure_before)
      .def_readonly("structure_after", &Diagnosis::structure_after)
      .def_readonly("findings", &Diagnosis::findings)
      .def_readonly("ambiguous", &Diagnosis::ambiguous)
      .def_readonly("unobservable", &Diagnosis::unobservable)
      .def_readonly("unexplained", &Diagnosis::unexplained)
      .def_readonly("baseline_fit", &Diagnosis::baseline_fit)
      .def_readonly("final_fit", &Diagnosis::final_fit)
      .def_readonly("noise", &Diagnosis::noise)
      .def_readonly("noise_whitened", &Diagnosis::noise_whitened)
      .def_readonly("angle_tables", &Diagnosis::angle_tables)
      .def_readonly("rounds", &Diagnosis::rounds)
      .def_readonly("seconds", &Diagnosis::seconds);

  m.def(
      "diagnose_ballbar",
      [](const BallbarSession& session, const DiagnosisOptions& options,
         const std::optional<BallbarSession>& reference) {
        pyb::gil_scoped_release release;
        return diagnose_ballbar(session, options, reference.value_or(BallbarSession{}));
      },
      pyb::arg("session"), pyb::arg("options") = DiagnosisOptions{},
      pyb::arg("reference") = std::nullopt,
      "Diagnose a ballbar session: baseline fit, residual structure, catalogue candidates, "
      "findings with their gain.");

  m.def(
      "diagnose_rtest",
      [](const RtestSession& session, const DiagnosisOptions& options) {
        pyb::gil_scoped_release release;
        return diagnose_rtest(session, options);
      },
      pyb::arg("session"), pyb::arg("options") = DiagnosisOptions{},
      "Diagnose an R-test session (baseline: location errors and a probe zero per set-up).");
  m.def(
      "budget_diagnosis_ballbar",
      [](const BallbarSession& session, const DiagnosisOptions& options) {
        pyb::gil_scoped_release release;
        return budget_diagnosis_ballbar(session, options);
      },
      pyb::arg("session"), pyb::arg("options") = DiagnosisOptions{},
      "The diagnosis a budget rests on: a long session searched on a reduced design, what it "
      "found diagnosed on every reading (diagnose/ballbar_diagnosis.hpp).");
}

}  // namespace

void bind_diagnose(pyb::module_& m) {
  bind_diagnosis_findings(m);
  bind_diagnosis_report(m);
}

}  // namespace rotacal::py
