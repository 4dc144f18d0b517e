// Bindings for include/rotacal/ballbar/design.hpp: the ballbar test design.
#include "numpy.hpp"
#include "rotacal/ballbar/design.hpp"

namespace rotacal::py {

void bind_design(pyb::module_& m) {
  pyb::class_<BallbarDesignOptions>(m, "BallbarDesignOptions", "Options of design_ballbar_test (defaults).")
      .def(pyb::init<>())
      .def_readwrite("base", &BallbarDesignOptions::base, "the default set-up: machine, tests, ranges, feeds")
      .def_readwrite("bar_lengths_mm", &BallbarDesignOptions::bar_lengths_mm)
      .def_readwrite("pivot_x_mm", &BallbarDesignOptions::pivot_x_mm)
      .def_readwrite("pivot_z_mm", &BallbarDesignOptions::pivot_z_mm)
      .def_readwrite("travel_min", &BallbarDesignOptions::travel_min, "X, Y, Z, mm (formats.md frame)")
      .def_readwrite("travel_max", &BallbarDesignOptions::travel_max)
      .def_readwrite("time_budget_s", &BallbarDesignOptions::time_budget_s, "0: the default set-up's run time")
      .def_readwrite("sample_rate_hz", &BallbarDesignOptions::sample_rate_hz)
      .def_readwrite("noise_um", &BallbarDesignOptions::noise_um)
      .def_readwrite("noise_rho", &BallbarDesignOptions::noise_rho, "AR(1) coefficient between samples")
      .def_readwrite("reference_radius_mm", &BallbarDesignOptions::reference_radius_mm)
      .def_property(
          "effects_of_concern", [](const BallbarDesignOptions& o) { return ids_of(o.effects_of_concern); },
          [](BallbarDesignOptions& o, const std::vector<std::string>& ids) { o.effects_of_concern = effects_of(ids); });
  pyb::class_<DesignCandidate>(m, "DesignCandidate", "One set-up, evaluated.")
      .def_readonly("setup", &DesignCandidate::setup)
      .def_readonly("feasible", &DesignCandidate::feasible)
      .def_readonly("why_not", &DesignCandidate::why_not)
      .def_readonly("duration_s", &DesignCandidate::duration_s)
      .def_readonly("names", &DesignCandidate::names)
      .def_readonly("sigma", &DesignCandidate::sigma, "predicted 1 sigma at the time budget (mm, rad)")
      .def_readonly("worst_expanded_um", &DesignCandidate::worst_expanded_um)
      .def_readonly("worst_error", &DesignCandidate::worst_error)
      .def_readonly("effect_vs_location", &DesignCandidate::effect_vs_location)
      .def_readonly("effect_vs_effects", &DesignCandidate::effect_vs_effects);
  pyb::class_<BallbarDesign>(m, "BallbarDesign", "The chosen set-up and the default one.")
      .def_readonly("best", &BallbarDesign::best)
      .def_readonly("baseline", &BallbarDesign::baseline)
      .def_readonly("time_budget_s", &BallbarDesign::time_budget_s)
      .def_readonly("ratio", &BallbarDesign::ratio)
      .def_readonly("candidates", &BallbarDesign::candidates);
  m.def(
      "design_ballbar_test",
      [](const BallbarDesignOptions& o) {
        pyb::gil_scoped_release release;
        return design_ballbar_test(o);
      },
      pyb::arg("options"), "The pivot and bar length with the smallest predicted uncertainty (ballbar/design.hpp).");
}

}  // namespace rotacal::py
