// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/realtime/ (the controller's real-time evaluation of a fitted
// model) and io/realtime_export.hpp: the same forward() and inverse() a controller runs, on the
// same blob it loads.
#include "numpy.hpp"
#include "rotacal/io/realtime_export.hpp"
#include "rotacal/io/thermal_model.hpp"
#include "rotacal/realtime/blob.hpp"
#include "rotacal/realtime/evaluate.hpp"

namespace rotacal::py {

namespace {
using Rows5 = Eigen::Matrix<double, Eigen::Dynamic, 5, Eigen::RowMajor>;

realtime::State state_of(double tool_length, double y1, double y2, double t) {
  realtime::State s;
  s.tool_length = tool_length;
  s.y1 = y1;
  s.y2 = y2;
  s.t = t;
  return s;
}

realtime::Joints joints_of(const Rows5& a, Eigen::Index i) {
  realtime::Joints q;
  q.xyz = a.row(i).head<3>().transpose();
  q.angles = {a(i, 3), a(i, 4)};
  return q;
}
}  // namespace

void bind_realtime(pyb::module_& m) {
  pyb::class_<realtime::Model>(
      m, "RealtimeModel",
      "A fitted model as a controller's real-time path holds it (realtime/model.hpp).")
      .def_property_readonly("num_effects", [](const realtime::Model& r) { return r.num_effects; })
      .def_property_readonly(
          "fingerprint", [](const realtime::Model& r) { return realtime::machine_fingerprint(r); })
      .def(
          "blob", [](const realtime::Model& r) { return pyb::bytes(realtime::encode(r)); },
          "The blob a controller loads (realtime/blob.hpp).")
      .def(
          "forward",
          [](const realtime::Model& r, const Array& joints, double tool_length, double y1,
             double y2, double t) {
            const Rows5 q = rows_of<5>(joints, "joints");
            const realtime::State s = state_of(tool_length, y1, y2, t);
            Rows3 tip(q.rows(), 3), dir(q.rows(), 3);
            {
              pyb::gil_scoped_release release;
              for (Eigen::Index i = 0; i < q.rows(); ++i) {
                const realtime::ToolPose p = realtime::forward(r, joints_of(q, i), s);
                tip.row(i) = p.tip.transpose();
                dir.row(i) = p.direction.transpose();
              }
            }
            return pyb::make_tuple(tip, dir);
          },
          pyb::arg("joints"), pyb::arg("tool_length") = 0.0, pyb::arg("y1") = 0.0,
          pyb::arg("y2") = 0.0, pyb::arg("t") = 0.0,
          "(tip (N, 3) mm, direction (N, 3)) relative to the workpiece for joints (N, 5): x, y, "
          "z (mm), tilt, rot (rad); y1, y2 the thermal lag states, t the time (s) of the "
          "thermal_drift / thermal_warmup terms.")
      .def(
          "inverse",
          [](const realtime::Model& r, const Array& world, double tool_length, double y1, double y2,
             double t) {
            const Rows5 w = rows_of<5>(world, "world");
            const realtime::State s = state_of(tool_length, y1, y2, t);
            Rows5 q(w.rows(), 5);
            Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor> err(w.rows(), 2);
            {
              pyb::gil_scoped_release release;
              for (Eigen::Index i = 0; i < w.rows(); ++i) {
                const realtime::InverseResult x = realtime::inverse(r, joints_of(w, i), s);
                q.row(i) << x.joints.xyz.transpose(), x.joints.angles.tilt, x.joints.angles.rot;
                err.row(i) << x.tip_error, x.direction_error;
              }
            }
            return pyb::make_tuple(q, err);
          },
          pyb::arg("world"), pyb::arg("tool_length") = 0.0, pyb::arg("y1") = 0.0,
          pyb::arg("y2") = 0.0, pyb::arg("t") = 0.0,
          "(joints (N, 5), residual (N, 2): tip mm, direction rad) for world (N, 5): the tool "
          "tip relative to the workpiece (mm) and the nominal rotary angles (rad).");
  m.def(
      "realtime_model_of_file",
      [](const std::string& path, bool thermal) {
        return thermal ? realtime_model(read_thermal_model(path), path)
                       : realtime_model(read_model(path), path);
      },
      pyb::arg("path"), pyb::arg("thermal") = false,
      "The real-time model of a model file (io/realtime_export.hpp): every location error and "
      "effect; thermal (a model of kind thermal): its cold errors and each lag's gains.");
  m.def(
      "realtime_model_of_blob",
      [](const pyb::bytes& data, std::optional<MachineType> machine, const std::string& source) {
        return read_realtime_blob(std::string(data), machine ? &*machine : nullptr, source);
      },
      pyb::arg("data"), pyb::arg("machine") = std::nullopt, pyb::arg("source") = "<blob>",
      "Read a blob (realtime/blob.hpp); ParseError naming the field when it is corrupt, "
      "truncated, of another version or (given machine) of another machine.");
}

}  // namespace rotacal::py
