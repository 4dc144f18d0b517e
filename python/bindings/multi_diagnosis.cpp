// SPDX-License-Identifier: BSD-3-Clause
// Bindings for one diagnosis of several sessions of one machine (diagnose/multi_session.hpp).
// Thin: the (name, session) pairs in, the result's fields out.
#include <pybind11/stl.h>

#include "numpy.hpp"
#include "rotacal/diagnose/multi_session.hpp"
#include "rotacal/session/probe_session.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal::py {

void bind_multi_diagnosis(pyb::module_& m) {
  pyb::class_<MultiDiagnosis::Session>(m, "MultiDiagnosisSession")
      .def_readonly("name", &MultiDiagnosis::Session::name)
      .def_readonly("instrument", &MultiDiagnosis::Session::instrument)
      .def_readonly("n", &MultiDiagnosis::Session::n)
      .def_readonly("noise_um", &MultiDiagnosis::Session::noise_um)
      .def_readonly("weight", &MultiDiagnosis::Session::weight)
      .def_readonly("rms_before_um", &MultiDiagnosis::Session::rms_before_um)
      .def_readonly("rms_after_um", &MultiDiagnosis::Session::rms_after_um);
  pyb::class_<MultiDiagnosis>(m, "MultiDiagnosis")
      .def_readonly("diagnosis", &MultiDiagnosis::diagnosis)
      .def_readonly("sessions", &MultiDiagnosis::sessions)
      .def_readonly("where", &MultiDiagnosis::where)
      .def_readonly("notes", &MultiDiagnosis::notes);
  m.def("is_machine_effect", &is_machine_effect, pyb::arg("effect"),
        "True for an effect of the machine (one parameter set shared by every session).");
  m.def(
      "diagnose_sessions",
      [](const std::vector<std::pair<std::string, pyb::object>>& sessions,
         const DiagnosisOptions& options) {
        std::vector<DiagnosisSession> in;
        for (const auto& [name, s] : sessions) {
          if (pyb::isinstance<BallbarSession>(s))
            in.push_back(DiagnosisSession::of(name, s.cast<BallbarSession>()));
          else if (pyb::isinstance<RtestSession>(s))
            in.push_back(DiagnosisSession::of(name, s.cast<RtestSession>()));
          else if (pyb::isinstance<ProbeSession>(s))
            in.push_back(DiagnosisSession::of(name, s.cast<ProbeSession>()));
          else
            throw InvalidArgument("diagnose: session " + name +
                                  " is not a ballbar, R-test or touch-probe session");
        }
        pyb::gil_scoped_release release;
        return diagnose_sessions(std::move(in), options);
      },
      pyb::arg("sessions"), pyb::arg("options") = DiagnosisOptions{},
      "One diagnosis of several (name, session) pairs of one machine "
      "(diagnose/multi_session.hpp): machine effects shared, instrument, set-up and time effects "
      "per session (ids 'name:id').");
}

}  // namespace rotacal::py
