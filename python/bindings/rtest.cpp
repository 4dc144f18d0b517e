// Bindings for include/rotacal/rtest (identification and error map; the C++ module does the work).
#include "numpy.hpp"
#include "rotacal/rtest/error_map.hpp"

namespace rotacal::py {

void bind_rtest(pyb::module_& m) {
  pyb::class_<RtestJointIdentification>(m, "RtestJointIdentification")
      .def_readonly("method", &RtestJointIdentification::method)
      .def_readonly("parameters", &RtestJointIdentification::parameters)
      .def_readonly("covariance", &RtestJointIdentification::covariance)
      .def_readonly("probe_zeros", &RtestJointIdentification::probe_zeros)
      .def_readonly("residual_rms_um", &RtestJointIdentification::residual_rms_um)
      .def_readonly("sigma_um", &RtestJointIdentification::sigma_um)
      .def_readonly("n_samples", &RtestJointIdentification::n_samples)
      .def_readonly("converged", &RtestJointIdentification::converged)
      .def_readonly("iterations", &RtestJointIdentification::iterations)
      .def_readonly("unobservable", &RtestJointIdentification::unobservable)
      .def_readonly("notes", &RtestJointIdentification::notes);

  pyb::class_<RtestPaperIdentification>(m, "RtestPaperIdentification")
      .def_readonly("method", &RtestPaperIdentification::method)
      .def_readonly("b_deg", &RtestPaperIdentification::b_deg)
      .def_readonly("c_deg", &RtestPaperIdentification::c_deg)
      .def_readonly("residual_rms_um", &RtestPaperIdentification::residual_rms_um)
      .def_readonly("n_samples", &RtestPaperIdentification::n_samples)
      .def_readonly("unobservable", &RtestPaperIdentification::unobservable)
      .def_readonly("notes", &RtestPaperIdentification::notes);

  m.def(
      "identify_rtest_joint",
      [](const RtestSession& session) {
        pyb::gil_scoped_release release;
        return identify_joint(session);
      },
      pyb::arg("session"),
      "Joint Ceres fit of an R-test session: location errors, smooth B and C maps, a probe zero "
      "per set-up, with observability (rtest/identify_joint.hpp).");
  m.def(
      "identify_rtest_paper",
      [](const RtestSession& session) {
        pyb::gil_scoped_release release;
        return identify_paper(session);
      },
      pyb::arg("session"), "Oyama & Ibaraki's method, Eqs. 10-22 (rtest/identify_paper.hpp).");
  m.def(
      "rtest_error_map",
      [](const RtestJointIdentification& id, const std::vector<double>& b_deg,
         const std::vector<double>& c_deg, const std::string& format) {
        const RtestErrorMap map = error_map(id, b_deg, c_deg);
        return format == "csv" ? error_map_csv(map) : error_map_json(map);
      },
      pyb::arg("identification"), pyb::arg("b_deg"), pyb::arg("c_deg"), pyb::arg("format") = "json",
      "The joint model's error map on a grid (deg), as JSON or CSV text.");
  m.def(
      "rtest_error_map",
      [](const RtestPaperIdentification& id, const std::string& format) {
        const RtestErrorMap map = error_map(id);
        return format == "csv" ? error_map_csv(map) : error_map_json(map);
      },
      pyb::arg("identification"), pyb::arg("format") = "json",
      "The paper method's error map at its measured grid, as JSON or CSV text.");
}

}  // namespace rotacal::py
