// SPDX-License-Identifier: BSD-3-Clause
// Bindings for one identification from several sessions of one machine (multi/identify.hpp).
// Thin: the sessions in, the result's fields out.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <map>

#include "json_value.hpp"
#include "numpy.hpp"
#include "rotacal/multi/identify.hpp"
#include "rotacal/multi/model_document.hpp"
#include "rotacal/session/probe_session.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal::py {

void bind_multi(pyb::module_& m) {
  pyb::class_<MultiDisagreement>(m, "MultiDisagreement")
      .def_readonly("parameter", &MultiDisagreement::parameter)
      .def_readonly("unit", &MultiDisagreement::unit)
      .def_readonly("session_a", &MultiDisagreement::session_a)
      .def_readonly("session_b", &MultiDisagreement::session_b)
      .def_readonly("value_a", &MultiDisagreement::value_a)
      .def_readonly("value_b", &MultiDisagreement::value_b)
      .def_readonly("difference", &MultiDisagreement::difference)
      .def_readonly("sigma", &MultiDisagreement::sigma)
      .def_readonly("z", &MultiDisagreement::z)
      .def_readonly("dof", &MultiDisagreement::dof, "of sigma (Welch-Satterthwaite)")
      .def_readonly("threshold", &MultiDisagreement::threshold, "abs(z) beyond which it disagrees");
  pyb::class_<MultiSessionResult>(m, "MultiSessionResult")
      .def_readonly("name", &MultiSessionResult::name)
      .def_readonly("instrument", &MultiSessionResult::instrument)
      .def_readonly("nuisances", &MultiSessionResult::nuisances)
      .def_readonly("alone", &MultiSessionResult::alone)
      .def_readonly("noise", &MultiSessionResult::noise)
      .def_readonly("noise_refit", &MultiSessionResult::noise_refit)
      .def_readonly("noise_correction", &MultiSessionResult::noise_correction)
      .def_readonly("residual_rms_um", &MultiSessionResult::residual_rms_um)
      .def_readonly("n_residuals", &MultiSessionResult::n_residuals)
      .def_readonly("dof", &MultiSessionResult::dof, "of its sigmas alone");
  pyb::class_<MultiIdentification, Identification>(
      m, "MultiIdentification",
      "The joint identification: blocks 'location_errors', 'effects', then one per session.")
      .def_readonly("machine", &MultiIdentification::machine)
      .def_property_readonly("location_errors", &MultiIdentification::location_errors)
      .def_property_readonly("effects", &MultiIdentification::effects)
      .def_readonly("sessions", &MultiIdentification::sessions)
      .def_readonly("disagreements", &MultiIdentification::disagreements)
      .def_readonly("sigma_inflated", &MultiIdentification::sigma_inflated)
      .def_readonly("comparisons", &MultiIdentification::comparisons)
      .def_readonly("disagreement_z", &MultiIdentification::disagreement_z);

  m.def(
      "identify_multi",
      [](const std::vector<std::pair<std::string, pyb::object>>& sessions, const std::string& noise,
         const std::vector<std::string>& effects, bool inflate_sigma,
         const std::map<std::string, std::string>& same_setup) {
        std::vector<MultiSessionInput> in;
        for (const auto& [name, s] : sessions) {
          if (pyb::isinstance<BallbarSession>(s))
            in.push_back(MultiSessionInput::of(name, s.cast<BallbarSession>()));
          else if (pyb::isinstance<RtestSession>(s))
            in.push_back(MultiSessionInput::of(name, s.cast<RtestSession>()));
          else if (pyb::isinstance<ProbeSession>(s))
            in.push_back(MultiSessionInput::of(name, s.cast<ProbeSession>()));
          else
            throw InvalidArgument("identify: session " + name +
                                  " is not a ballbar, R-test or touch-probe session");
          const auto earlier = same_setup.find(name);
          if (earlier != same_setup.end()) in.back().same_setup_as = earlier->second;
        }
        for (const auto& [later, earlier] : same_setup)
          if (std::none_of(in.begin(), in.end(),
                           [&](const MultiSessionInput& s) { return s.name == later; }))
            throw InvalidArgument("identify: same_setup names session " + later +
                                  ", which is not among the sessions");
        MultiFitOptions o;
        o.noise.noise = noise_handling_from_string(noise);
        o.effects = effects_of(effects);
        o.inflate_sigma = inflate_sigma;
        pyb::gil_scoped_release release;
        return identify_multi(in, o);
      },
      pyb::arg("sessions"), pyb::arg("noise") = "auto",
      pyb::arg("effects") = std::vector<std::string>{}, pyb::arg("inflate_sigma") = false,
      pyb::arg("same_setup") = std::map<std::string, std::string>{},
      "One identification from several (name, session) pairs of one machine (multi/identify.hpp): "
      "one set of location errors (and of the catalogue effects `effects`), each session's own "
      "nuisances and noise model, and the "
      "disagreements between the sessions fitted alone; noise 'auto' or 'white'; inflate_sigma: "
      "widen the sigmas of disagreeing parameters by their Birge ratio; same_setup: session name "
      "-> the earlier session whose set-up it continues, sharing its own parameters (pivot, nest "
      "zeros).");
  m.def("refuse_disagreeing", &refuse_disagreeing, pyb::arg("identification"),
        "InvalidArgument naming every disagreement unless there is none or the sigmas were "
        "widened for them (multi/model_document.hpp).");
  m.def(
      "multi_model_document",
      [](const MultiIdentification& identification) {
        return from_json(multi_model_document(identification));
      },
      pyb::arg("identification"),
      "The rotacal-model/1 document (kind multi) of one identification from several sessions "
      "(rotacal/multi/model_document.hpp).");
}

}  // namespace rotacal::py
