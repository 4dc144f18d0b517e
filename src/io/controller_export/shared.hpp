// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The part of the controller exports that every controller shares (controller_export/*.cpp):
// the axis lines as linear maps of the location errors, one parameter's corrected value and
// its sigma, corrected axis vectors, the header of the file, and where each error goes.
#include <Eigen/Core>
#include <array>
#include <sstream>
#include <string>

#include "rotacal/io/controller_comment.hpp"
#include "rotacal/io/controller_export.hpp"

namespace rotacal::export_detail {

using Row = Eigen::Matrix<double, 1, 8>;
using Map3 = Eigen::Matrix<double, 3, 8>;  // a 3-vector as a linear function of the 8 errors

// The line offsets of ../shared/spec/formats.md as linear maps of the error vector: the tilt
// axis (A or B) and C, their point offsets dp and direction offsets dn. The lines are linear in
// the errors, so each column is the one definition (kinematics/machine.hpp) at a unit error.
struct LineMaps {
  Map3 tilt_point = Map3::Zero(), tilt_dir = Map3::Zero(), c_point = Map3::Zero(),
       c_dir = Map3::Zero();
  Eigen::Vector3d tilt_axis, c_axis;
  char tilt = 'A';
};

LineMaps line_maps(MachineType m);

// One parameter: its current value plus scale * (coefficients . errors).
struct Param {
  std::string name, unit;
  Row coef = Row::Zero();
  double scale = 1.0;
  bool written = true;
};

std::string fixed(double v, int digits);

double current_of(const ExportOptions& o, const std::string& name, double fallback = 0.0);

ControllerValue value_of(const Param& p, double current, const ExportInput& in);

// A unit axis vector corrected by a small direction offset: normalize(u + s dn), where u is
// the current vector (or the nominal axis) and s = +-1 its sense against the nominal axis
// (formats.md: for a negated direction the offset is negated too).
struct AxisVector {
  Eigen::Vector3d corrected;
  Eigen::Vector3d current;
  Map3 coef;  // first-order d corrected / d errors
};

AxisVector corrected_axis(const Eigen::Vector3d& current_raw, const Eigen::Vector3d& nominal,
                          const Map3& dn, const ExportInput& in, const std::string& what,
                          double default_sense = 1.0);

ControllerValue vector_component(const std::string& name, const AxisVector& a, int k,
                                 const ExportInput& in, const Map3& dn);

// The file: comment lines through the dialect's comment writer (a model path, a session or
// a date may hold any text), then the values.
struct Writer {
  explicit Writer(CommentDialect d) : dialect(d) {}
  CommentDialect dialect;
  std::ostringstream out;
  void line(const std::string& s = "") {
    for (const std::string& l : comment_lines(dialect, s)) out << l << "\n";
  }
};

ControllerExport new_export(Controller c, const std::string& kinematics,
                            const std::string& file_kind, const ExportOptions& o);

void header(Writer& w, const ControllerExport& ex, const ExportInput& in, const ExportOptions& o,
            const std::string& title);

void dispositions(ControllerExport& ex, const ExportInput& in,
                  const std::array<std::string, 8>& where, const std::array<bool, 8>& held);

// One export per controller (linuxcnc.cpp, sinumerik.cpp, isg.cpp, heidenhain.cpp, fanuc.cpp).
ControllerExport export_linuxcnc(const ExportInput& in, const ExportOptions& o);
ControllerExport export_siemens(const ExportInput& in, const ExportOptions& o);
ControllerExport export_isg(const ExportInput& in, const ExportOptions& o);
ControllerExport export_heidenhain(const ExportInput& in, const ExportOptions& o);
ControllerExport export_fanuc(const ExportInput& in, const ExportOptions& o);

// The head machines LinuxCNC ships a kinematics module for (linuxcnc_heads.cpp): "maxkins" for
// B-head-C-table, "5axiskins" for BC-head, "" for any other machine.
std::string linuxcnc_head_kinematics(MachineType m);
ControllerExport export_linuxcnc_head(const ExportInput& in, const ExportOptions& o);

}  // namespace rotacal::export_detail
