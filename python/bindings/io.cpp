// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/io: session classes with numpy columns, readers and writers.
#include "json_value.hpp"
#include "numpy.hpp"
#include "rotacal/ballbar/model_document.hpp"
#include "rotacal/core/json_text.hpp"
#include "rotacal/io/ballbar_file.hpp"
#include "rotacal/io/model_file.hpp"
#include "rotacal/io/output_file.hpp"
#include "rotacal/io/session_arrays.hpp"
#include "rotacal/rtest/model_document.hpp"
#include "rotacal/session/plausibility.hpp"

namespace rotacal::py {

pyb::object from_json(const nlohmann::ordered_json& j) {
  switch (j.type()) {
    case nlohmann::ordered_json::value_t::null:
      return pyb::none();
    case nlohmann::ordered_json::value_t::boolean:
      return pyb::bool_(j.get<bool>());
    case nlohmann::ordered_json::value_t::number_integer:
      return pyb::int_(j.get<long long>());
    case nlohmann::ordered_json::value_t::number_unsigned:
      return pyb::int_(j.get<unsigned long long>());
    case nlohmann::ordered_json::value_t::number_float:
      return pyb::float_(j.get<double>());
    case nlohmann::ordered_json::value_t::string:
      return pyb::str(j.get<std::string>());
    case nlohmann::ordered_json::value_t::array: {
      pyb::list out;
      for (const auto& x : j) out.append(from_json(x));
      return std::move(out);
    }
    case nlohmann::ordered_json::value_t::object: {
      pyb::dict out;
      for (auto it = j.begin(); it != j.end(); ++it)
        out[pyb::str(it.key())] = from_json(it.value());
      return std::move(out);
    }
    default:
      throw InvalidArgument("model document: a JSON value of an unsupported type");
  }
}

namespace {
pyb::dict metadata_dict(const Metadata& m) {
  pyb::dict d;
  for (const auto& kv : m) d[pyb::str(kv.first)] = kv.second;
  return d;
}
// Python objects <-> JSON values for model documents (dicts of str keys, lists, numbers, None).
nlohmann::ordered_json to_json(const pyb::handle& o, const std::string& where, int depth = 0) {
  if (depth > 64) throw InvalidArgument(where + ": nested too deeply");
  if (o.is_none()) return nullptr;
  if (pyb::isinstance<pyb::bool_>(o)) return o.cast<bool>();
  if (pyb::isinstance<pyb::int_>(o)) {
    try {
      return o.cast<long long>();
    } catch (const pyb::cast_error&) {
      throw InvalidArgument(where + ": integer out of range");
    }
  }
  if (pyb::isinstance<pyb::float_>(o)) return o.cast<double>();
  if (pyb::isinstance<pyb::str>(o)) return o.cast<std::string>();
  if (pyb::isinstance<pyb::dict>(o)) {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    for (const auto& kv : o.cast<pyb::dict>()) {
      if (!pyb::isinstance<pyb::str>(kv.first)) throw InvalidArgument(where + ": keys must be str");
      const std::string key = kv.first.cast<std::string>();
      out[key] = to_json(kv.second, where + "." + key, depth + 1);
    }
    return out;
  }
  if (pyb::isinstance<pyb::list>(o) || pyb::isinstance<pyb::tuple>(o)) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    std::size_t i = 0;
    for (const auto& x : o)
      out.push_back(to_json(x, where + "[" + std::to_string(i++) + "]", depth + 1));
    return out;
  }
  if (pyb::hasattr(o, "tolist")) return to_json(o.attr("tolist")(), where, depth + 1);  // numpy
  throw InvalidArgument(where + ": a " + std::string(pyb::str(o.get_type().attr("__name__"))) +
                        " cannot be written as JSON");
}

// The session classes, their readers and writers.
void bind_sessions(pyb::module_& m) {
  pyb::class_<BallbarSession>(m, "BallbarSession", "A rotacal-ballbar/1 session (mm, deg, s).")
      .def(pyb::init(&make_ballbar_session), pyb::arg("machine"), pyb::arg("ballbar_length"),
           pyb::arg("pivot"), pyb::arg("tests"), pyb::arg("time"), pyb::arg("xyz"),
           pyb::arg("angles_deg"), pyb::arg("length"), pyb::arg("noise_um") = std::nullopt,
           "Build a session from columns: tests (N labels), time (N,), xyz (N,3) tool cup, "
           "angles_deg (N,2) tilt and C, length (N,) measured lengths.")
      .def_readonly("machine", &BallbarSession::machine)
      .def_readonly("ballbar_length", &BallbarSession::ballbar_length)
      .def_property_readonly("pivot",
                             [](const BallbarSession& s) { return Eigen::Vector3d(s.pivot); })
      .def_readonly("noise_um", &BallbarSession::noise_um)
      .def_property_readonly("metadata",
                             [](const BallbarSession& s) { return metadata_dict(s.metadata); })
      .def_readonly("warnings", &BallbarSession::warnings,
                    "what the reader found suspicious but kept")
      .def_property_readonly("tests", &ballbar_tests, "test label of every sample")
      .def_property_readonly("test_names", &BallbarSession::tests, "distinct test labels, in order")
      .def_property_readonly("time", &ballbar_times)
      .def_property_readonly("xyz", &ballbar_xyz)
      .def_property_readonly("angles_deg", &ballbar_angles_deg)
      .def_property_readonly("length", &ballbar_lengths)
      .def_property_readonly("annotations",
                             [](const BallbarSession& s) {
                               std::vector<std::pair<std::size_t, std::string>> out;
                               for (const Annotation& a : s.annotations)
                                 out.emplace_back(a.before_sample, a.text);
                               return out;
                             })
      .def("with_lengths", &with_lengths, pyb::arg("length"),
           "The same session with other lengths (e.g. a model's prediction).")
      .def("__len__", [](const BallbarSession& s) { return s.samples.size(); })
      .def("__repr__", [](const BallbarSession& s) {
        return "<BallbarSession " + to_string(s.machine) + ", " + std::to_string(s.samples.size()) +
               " samples, L0 = " + format_number(s.ballbar_length) + " mm>";
      });

  pyb::class_<RtestSession>(m, "RtestSession", "A rotacal-rtest/1 session (mm, deg, s).")
      .def_readonly("machine", &RtestSession::machine)
      .def_readonly("nests", &RtestSession::nests)
      .def_readonly("probe_dirs", &RtestSession::probe_dirs)
      .def_readonly("noise_um", &RtestSession::noise_um)
      .def_property_readonly("metadata",
                             [](const RtestSession& s) { return metadata_dict(s.metadata); })
      .def_readonly("warnings", &RtestSession::warnings,
                    "what the reader found suspicious but kept")
      .def_property_readonly("setups", &rtest_setups, "set-up (nest) label of every pose")
      .def_property_readonly("time", &rtest_times)
      .def_property_readonly("angles_deg", &rtest_angles_deg)
      .def_property_readonly("xyz", &rtest_xyz)
      .def_property_readonly("d", &rtest_displacements, "dx, dy, dz (N,3), table frame, mm")
      .def("with_displacements", &with_displacements, pyb::arg("d"))
      .def("__len__", [](const RtestSession& s) { return s.samples.size(); })
      .def("__repr__", [](const RtestSession& s) {
        return "<RtestSession " + to_string(s.machine) + ", " + std::to_string(s.samples.size()) +
               " poses, " + std::to_string(s.nests.size()) + " nests>";
      });

  m.def("read_session", &read_session, pyb::arg("path"),
        "Read a rotacal-ballbar/1 or rotacal-rtest/1 file (chosen by its format line).");
  m.def("read_ballbar", &read_ballbar, pyb::arg("path"));
  m.def("read_rtest", &read_rtest, pyb::arg("path"));
  m.def("write_ballbar", &write_ballbar, pyb::arg("session"), pyb::arg("path"));
  m.def("write_rtest", &write_rtest, pyb::arg("session"), pyb::arg("path"));
  m.def("format_ballbar", &format_ballbar, pyb::arg("session"));
  m.def("format_rtest", &format_rtest, pyb::arg("session"));
}

// Model files (rotacal/io/model_file.hpp): documents as dicts, validated and written in C++.
void bind_model_documents(pyb::module_& m) {
  m.def(
      "read_model_document",
      [](const std::string& path) { return from_json(read_model_document(path)); },
      pyb::arg("path"),
      "Read a rotacal-model file (strict JSON, version, kind, machine checked); the document as a "
      "dict. ParseError (syntax), InvalidArgument (content), IoError.");
  m.def(
      "parse_model_document",
      [](const std::string& text, const std::string& source) {
        return from_json(parse_model(text, source).document);
      },  // full check
      pyb::arg("text"), pyb::arg("source") = "<model>");
  m.def(
      "format_model_document",
      [](const pyb::dict& doc, const std::string& source) {
        return format_model(to_json(doc, source), source);
      },
      pyb::arg("document"), pyb::arg("source") = "model",
      "Strict JSON text of a model document (non-finite numbers as null with a reason), "
      "validated.");
  m.def(
      "write_model_document",
      [](const pyb::dict& doc, const std::string& path, const std::vector<std::string>& inputs,
         const std::vector<std::string>& other_outputs) {
        nlohmann::ordered_json j = to_json(doc, path);
        pyb::gil_scoped_release release;
        write_model(j, path, OutputOptions{inputs, other_outputs});
      },
      pyb::arg("document"), pyb::arg("path"), pyb::arg("inputs") = std::vector<std::string>{},
      pyb::arg("other_outputs") = std::vector<std::string>{});
  m.def(
      "ballbar_model_from_document",
      [](const pyb::dict& doc, const std::string& source) {
        return ballbar_machine_model(model_from_json(to_json(doc, source), source));
      },
      pyb::arg("document"), pyb::arg("source") = "<model>");
  m.def(
      "ballbar_model_document",
      [](const BallbarMachineModel& model) { return from_json(ballbar_model_document(model)); },
      pyb::arg("model"));
  m.def(
      "rtest_joint_model_document",
      [](const RtestJointIdentification& identification,
         const std::map<std::string, Eigen::Vector3d>& nests) {
        return from_json(rtest_joint_model_document(identification, nests));
      },
      pyb::arg("identification"), pyb::arg("nests"),
      "The rotacal-model/1 document (kind rtest-joint) of a joint R-test identification "
      "(rotacal/rtest/model_document.hpp); nests: label -> nominal ball centre, mm.");
}

// The checks before fitting and before writing.
void bind_checks(pyb::module_& m) {
  // Plausibility before fitting (rotacal/session/plausibility.hpp).
  pyb::class_<PlausibilityOptions>(m, "PlausibilityOptions",
                                   "Limits of the plausibility checks (mm, deg).")
      .def(pyb::init<>())
      .def_readwrite("max_length_deviation_mm", &PlausibilityOptions::max_length_deviation_mm)
      .def_readwrite("max_position_deviation_mm", &PlausibilityOptions::max_position_deviation_mm)
      .def_readwrite("max_displacement_mm", &PlausibilityOptions::max_displacement_mm)
      .def_readwrite("min_ballbar_length_mm", &PlausibilityOptions::min_ballbar_length_mm)
      .def_readwrite("min_rotary_span_deg", &PlausibilityOptions::min_rotary_span_deg);
  pyb::class_<PlausibilityReport>(m, "PlausibilityReport")
      .def_readonly("median_deviation_mm", &PlausibilityReport::median_deviation_mm)
      .def_readonly("max_deviation_mm", &PlausibilityReport::max_deviation_mm)
      .def_readonly("worst_sample", &PlausibilityReport::worst_sample)
      .def_readonly("tilt_span_deg", &PlausibilityReport::tilt_span_deg)
      .def_readonly("rot_span_deg", &PlausibilityReport::rot_span_deg);
  m.def("check_plausible",
        pyb::overload_cast<const BallbarSession&, const std::string&, const PlausibilityOptions&>(
            &check_plausible),
        pyb::arg("session"), pyb::arg("source"), pyb::arg("options") = PlausibilityOptions{},
        "Refuse (InvalidArgument, likely cause named) a session the nominal kinematics cannot "
        "explain.");
  m.def("check_plausible",
        pyb::overload_cast<const RtestSession&, const std::string&, const PlausibilityOptions&>(
            &check_plausible),
        pyb::arg("session"), pyb::arg("source"), pyb::arg("options") = PlausibilityOptions{});
  m.def("check_plausible",
        pyb::overload_cast<const ProbeSession&, const std::string&, const PlausibilityOptions&>(
            &check_plausible),
        pyb::arg("session"), pyb::arg("source"), pyb::arg("options") = PlausibilityOptions{});
  m.def("check_model_machine", &check_model_machine, pyb::arg("model_machine"),
        pyb::arg("session_machine"), pyb::arg("model_source"));

  // The output rule (rotacal/io/output_file.hpp). The GIL is released: a FIFO blocks until read.
  m.def(
      "write_output",
      [](const std::string& path, const pyb::bytes& data, const std::vector<std::string>& inputs,
         const std::vector<std::string>& other_outputs) {
        std::string text = data;
        pyb::gil_scoped_release release;
        write_output(path, text, OutputOptions{inputs, other_outputs});
      },
      pyb::arg("path"), pyb::arg("data"), pyb::arg("inputs") = std::vector<std::string>{},
      pyb::arg("other_outputs") = std::vector<std::string>{},
      "Write bytes to path: regular files replaced atomically, devices and FIFOs written through; "
      "a directory, an input or another output is refused (IoError).");
  m.def(
      "check_output",
      [](const std::string& path, const std::vector<std::string>& inputs,
         const std::vector<std::string>& other_outputs) {
        return check_output(path, OutputOptions{inputs, other_outputs}) == OutputKind::WriteThrough
                   ? "write-through"
                   : "replace";
      },
      pyb::arg("path"), pyb::arg("inputs") = std::vector<std::string>{},
      pyb::arg("other_outputs") = std::vector<std::string>{},
      "Check an output path without writing: 'replace' or 'write-through'; raises IoError.");
  m.def(
      "check_json_bounds", &check_json_bounds, pyb::arg("text"), pyb::arg("source"),
      "Refuse JSON text nested deeper than 64 levels or with more objects and arrays than its size "
      "allows (core/json_text.hpp): ParseError naming source, line and column. The syntax is not "
      "checked.");
}

}  // namespace

void bind_io(pyb::module_& m) {
  bind_sessions(m);
  bind_model_documents(m);
  bind_checks(m);
}

}  // namespace rotacal::py
