// SPDX-License-Identifier: BSD-3-Clause
// Bindings for include/rotacal/rtest: device calibration, simulation, identification, error
// map and prediction. Thin: numpy in and out, the C++ module does the work.
#include <pybind11/stl.h>

#include <optional>

#include "numpy.hpp"
#include "rotacal/rtest/device.hpp"
#include "rotacal/rtest/error_map.hpp"
#include "rotacal/rtest/monte_carlo.hpp"
#include "rotacal/rtest/predict.hpp"
#include "rotacal/rtest/simulate.hpp"

namespace rotacal::py {

namespace {
using Rows6 = Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>;

// Evaluates f(row) -> (value, std) for each row of angles; returns both as (N, K) arrays.
template <int K, typename F>
std::pair<Eigen::Matrix<double, Eigen::Dynamic, K, Eigen::RowMajor>,
          Eigen::Matrix<double, Eigen::Dynamic, K, Eigen::RowMajor>>
evaluate_rows(Eigen::Index n, F f) {
  Eigen::Matrix<double, Eigen::Dynamic, K, Eigen::RowMajor> v(n, K), s(n, K);
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::Matrix<double, K, 1> sd;
    v.row(i) = f(i, sd).transpose();
    s.row(i) = sd.transpose();
  }
  return {v, s};
}

// The basis of the smooth error maps and the machines' map names.
void bind_rtest_basis(pyb::module_& m) {
  pyb::class_<RtestBasis>(
      m, "RtestBasis", "Smooth basis of the position-dependent errors (rtest/identify_joint.hpp).")
      .def(pyb::init([](int b_degree, int c_harmonics, int c_b_degree, bool gamma_cb) {
             RtestBasis b;
             b.b_degree = b_degree;
             b.c_harmonics = c_harmonics;
             b.c_b_degree = c_b_degree;
             b.gamma_cb = gamma_cb;
             return b;
           }),
           pyb::arg("b_degree") = RtestBasis{}.b_degree,
           pyb::arg("c_harmonics") = RtestBasis{}.c_harmonics,
           pyb::arg("c_b_degree") = RtestBasis{}.c_b_degree,
           pyb::arg("gamma_cb") = RtestBasis{}.gamma_cb)
      .def_readonly("b_degree", &RtestBasis::b_degree,
                    "highest power of b = B / 90 deg in the B map")
      .def_readonly("c_harmonics", &RtestBasis::c_harmonics, "harmonics 1..K of C in the C map")
      .def_readonly("c_b_degree", &RtestBasis::c_b_degree, "degree in b of the C-map coefficients")
      .def_readonly("gamma_cb", &RtestBasis::gamma_cb,
                    "gamma_CB (angular positioning of C) in the C map")
      .def_readonly("b_rotations", &RtestBasis::b_rotations,
                    "rotations in the tilt map (false for a head axis: for_machine)")
      .def_readonly("c_rotations", &RtestBasis::c_rotations,
                    "rotations in the rotary map (false for a head axis: for_machine)")
      .def("for_machine", &RtestBasis::for_machine, pyb::arg("machine"),
           "This basis with the rotations of head axes' maps left out (the sphere is one point).")
      .def(
          "coefficient_names",
          [](const RtestBasis& b, std::optional<MachineType> machine) {
            return machine ? b.coefficient_names(*machine) : b.coefficient_names();
          },
          pyb::arg("machine") = pyb::none(),
          "Names of the map coefficients, tilt-axis map first, in parameter order, with the "
          "machine's map names (rtest_map_names; BC-trt's 'BY', 'CB' when no machine is given).");
  m.def(
      "rtest_map_names",
      [](MachineType machine) {
        const auto n = rtest_map_names(machine);
        return std::vector<std::string>(n.begin(), n.end());
      },
      pyb::arg("machine"),
      "Names of a machine's two R-test error maps, [tilt axis' map, rotary axis' map], e.g. "
      "['BY', 'CB'] on BC-trt, ['BZ', 'CY'] on B-head-C-table.");
}

// The joint model: readings, table and tool errors and the maps, with 1-sigma.
void bind_rtest_joint_model(pyb::module_& m) {
  pyb::class_<RtestJointModel>(
      m, "RtestJointModel",
      "Location errors, tool_offset_Z (machines with head axes) and smooth error maps of the tilt "
      "and the rotary axis of any machine, with covariance.")
      .def(pyb::init([](MachineType machine, const RtestBasis& basis, const Eigen::VectorXd& params,
                        const Eigen::MatrixXd& covariance, const std::vector<bool>& observable) {
             return make_rtest_joint_model(machine, basis, params, covariance, observable);
           }),
           pyb::arg("machine"), pyb::arg("basis"), pyb::arg("params"), pyb::arg("covariance"),
           pyb::arg("observable"),
           "Rebuild a model from its parts (checked against the basis: rtest/predict.hpp).")
      .def_readonly("machine", &RtestJointModel::machine)
      .def_readonly("basis", &RtestJointModel::basis)
      .def_readonly("params", &RtestJointModel::params,
                    "8 location errors, tool_offset_Z (machines with head axes), then the map "
                    "coefficients (mm, rad): parameter_names() order")
      .def("parameter_names", &RtestJointModel::parameter_names,
           "Names of params in order: location errors, 'tool_offset_Z' on a machine with head "
           "axes, then the map coefficients.")
      .def_readonly("covariance", &RtestJointModel::covariance)
      .def_readonly("observable", &RtestJointModel::observable)
      .def(
          "readings",
          [](const RtestJointModel& mo, const Array& q, const Array& angles) {
            const Eigen::Vector3d qv = vec_of<3>(q, "q");
            const auto a = rows_of<2>(angles, "angles");
            return evaluate_rows<3>(a.rows(), [&](Eigen::Index i, Eigen::Vector3d& sd) {
              return mo.reading(qv, a(i, 0), a(i, 1), &sd);
            });
          },
          pyb::arg("q"), pyb::arg("angles"),
          "R-test readings (N, 3) of the nest at q (table frame, mm) at angles (N, 2) = (B, C) in "
          "rad, without probe zero, and their 1-sigma (N, 3) (NaN where an unobservable parameter "
          "enters).")
      .def(
          "table_errors",
          [](const RtestJointModel& mo, const Array& q, const Array& angles) {
            const Eigen::Vector3d qv = vec_of<3>(q, "q");
            const auto a = rows_of<2>(angles, "angles");
            return evaluate_rows<3>(a.rows(), [&](Eigen::Index i, Eigen::Vector3d& sd) {
              return mo.table_error(qv, a(i, 0), a(i, 1), &sd);
            });
          },
          pyb::arg("q"), pyb::arg("angles"),
          "Error T q - T_nominal q (N, 3) of the table point q (mm) at angles (N, 2) in rad, "
          "machine frame, mm, and its 1-sigma.")
      .def(
          "tool_errors",
          [](const RtestJointModel& mo, const Array& xyz, const Array& angles) {
            const auto p = rows_of<3>(xyz, "xyz");
            const auto a = rows_of<2>(angles, "angles");
            if (p.rows() != a.rows())
              throw InvalidArgument("tool_errors: xyz and angles need the same rows");
            return evaluate_rows<3>(a.rows(), [&](Eigen::Index i, Eigen::Vector3d& sd) {
              return mo.tool_error(p.row(i).transpose(), a(i, 0), a(i, 1), &sd);
            });
          },
          pyb::arg("xyz"), pyb::arg("angles"),
          "Error of the sphere (N, 3), actual - nominal, machine frame, mm, for commanded xyz (N, "
          "3) "
          "at angles (N, 2) = (tilt, rotary) in rad, and its 1-sigma; zero without head axes.")
      .def(
          "w_by",
          [](const RtestJointModel& mo, const Eigen::VectorXd& B) {
            return evaluate_rows<6>(B.size(), [&](Eigen::Index i, AxisErrors<double>& sd) {
              return mo.w_BY(B[i], &sd);
            });
          },
          pyb::arg("B"),
          "B-axis map (N, 6) = (dx, dy, dz, alpha, beta, gamma)_BY (mm, rad) at B (N,) in rad, "
          "and its 1-sigma.")
      .def(
          "w_cb",
          [](const RtestJointModel& mo, const Array& angles) {
            const auto a = rows_of<2>(angles, "angles");
            return evaluate_rows<6>(a.rows(), [&](Eigen::Index i, AxisErrors<double>& sd) {
              return mo.w_CB(a(i, 0), a(i, 1), &sd);
            });
          },
          pyb::arg("angles"),
          "C-axis map (N, 6) at angles (N, 2) = (B, C) in rad, and its 1-sigma.");
}

// The joint fit, the paper's method, Monte Carlo and the error maps.
void bind_rtest_identification(pyb::module_& m) {
  pyb::class_<RtestJointIdentification, Identification>(m, "RtestJointIdentification")
      .def_readonly("model", &RtestJointIdentification::model)
      .def_readonly("probe_zeros", &RtestJointIdentification::probe_zeros)
      .def_property_readonly(
          "residuals",
          [](const RtestJointIdentification& r) {
            return Eigen::MatrixXd(Eigen::Map<const Eigen::Matrix<double, -1, 3, Eigen::RowMajor>>(
                r.residuals.data(), static_cast<Eigen::Index>(r.residuals.size() / 3), 3));
          },
          "measured - model per sample (N, 3) = (dx, dy, dz), mm.");

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
      [](const RtestSession& session, const RtestBasis& basis, const std::string& noise) {
        RtestJointOptions o;
        o.basis = basis;
        o.noise.noise = noise_handling_from_string(noise);
        pyb::gil_scoped_release release;
        return identify_joint(session, o);
      },
      pyb::arg("session"), pyb::arg("basis") = RtestBasis{}, pyb::arg("noise") = "auto",
      "Joint fit of an R-test session: location errors, smooth B and C maps, a probe zero "
      "per set-up, with observability (rtest/identify_joint.hpp); noise 'auto' (AR noise model, "
      "GLS refit when correlated) or 'white'.");
  pyb::class_<RtestMonteCarlo>(m, "RtestMonteCarlo")
      .def_readonly("draws", &RtestMonteCarlo::draws)
      .def_readonly("noise", &RtestMonteCarlo::noise)
      .def_readonly("parameters", &RtestMonteCarlo::parameters)
      .def_readonly("values", &RtestMonteCarlo::values);
  m.def(
      "monte_carlo_rtest",
      [](const RtestSession& session, const RtestJointIdentification& result, int draws,
         std::uint64_t seed, const RtestBasis& basis, const pyb::object& progress) {
        RtestMonteCarloOptions o;
        o.draws = draws;
        o.seed = seed;
        o.fit.basis = basis;
        o.progress = progress_callback(progress);
        pyb::gil_scoped_release release;
        return monte_carlo(session, result, o);
      },
      pyb::arg("session"), pyb::arg("result"), pyb::arg("draws") = 100, pyb::arg("seed") = 1,
      pyb::arg("basis") = RtestBasis{}, pyb::arg("progress") = pyb::none(),
      "Monte Carlo check of an R-test joint fit's 1-sigma with the noise model fitted to the "
      "session (AR per nest and channel) when the fit used it, else white "
      "(rtest/monte_carlo.hpp).");
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

// Predicted sessions and their RMS.
void bind_rtest_prediction(pyb::module_& m) {
  m.def("predict_rtest_session", &predict_session, pyb::arg("model"), pyb::arg("session"),
        pyb::arg("probe_zeros") = std::map<std::string, Eigen::Vector3d>{},
        "The session with dx,dy,dz predicted by the model and 1-sigma columns dx_std, dy_std, "
        "dz_std; probe_zeros (set-up -> (3,) mm) are added if given (rtest/predict.hpp).");
  m.def(
      "rtest_prediction_rms_um",
      [](const RtestJointModel& mo, const RtestSession& session) {
        return prediction_rms_um(session, [&](const Eigen::Vector3d& q, double B, double C) {
          return mo.reading(q, B, C);
        });
      },
      pyb::arg("model"), pyb::arg("session"),
      "RMS (um) of measured - predicted readings after one constant offset per set-up.");
}

// The simulated pattern and session, and the simulator's noise-free readings.
void bind_rtest_simulation(pyb::module_& m) {
  // Bound so that the Python layer reads the simulator's defaults instead of restating them.
  pyb::class_<RtestPattern>(m, "RtestPattern", "The pose grid and nests of a simulated session.")
      .def(pyb::init<>())
      .def_readwrite("b_deg", &RtestPattern::b_deg, "B positions, deg (outer loop)")
      .def_readwrite("c_deg", &RtestPattern::c_deg, "C positions, deg (inner loop)")
      .def_property(
          "nests", [](const RtestPattern& p) { return rows_from(p.nests); },
          [](RtestPattern& p, const Array& a) { p.nests = vectors_of(a, "nests"); },
          "(K, 3) nominal ball centres, table frame, mm")
      .def_readwrite("dwell_s", &RtestPattern::dwell_s, "time between poses, s");
  m.def("default_rtest_pattern", &default_rtest_pattern, pyb::arg("machine"),
        "The paper's pattern fitted to a machine: tilt angles inside its limits (-90..90 every 30 "
        "deg where they allow), the rotary axis every 30 deg, the two paper nests halved until "
        "every commanded X, Y, Z is inside the travel (rtest/simulate.hpp).");
  m.def(
      "check_rtest_pattern",
      [](MachineType machine, const std::vector<double>& b_deg, const std::vector<double>& c_deg,
         const Array& nests) {
        RtestPattern p;
        p.b_deg = b_deg;
        p.c_deg = c_deg;
        p.nests = vectors_of(nests, "nests");
        check_rtest_pattern(machine, p, "R-test pattern");
      },
      pyb::arg("machine"), pyb::arg("b_deg"), pyb::arg("c_deg"), pyb::arg("nests"),
      "Raise InvalidArgument naming the axis and its limits (or the travel) when a tilt (b_deg) "
      "or rotary (c_deg) angle, deg, or a commanded X, Y, Z of a nest (K, 3) is outside the "
      "machine's limits.");
  pyb::class_<RtestSimOptions>(m, "RtestSimOptions", "Options of simulate_rtest (defaults).")
      .def(pyb::init<>())
      .def_readwrite("pattern", &RtestSimOptions::pattern)
      .def_readwrite("noise_um", &RtestSimOptions::noise_um, "1-sigma reading noise, um")
      .def_readwrite("probe_zero_um", &RtestSimOptions::probe_zero_um,
                     "1-sigma of each component of the per-set-up probe zero, um")
      .def_readwrite("write_d", &RtestSimOptions::write_d)
      .def_readwrite("seed", &RtestSimOptions::seed);
  m.def(
      "simulate_rtest",
      [](MachineType machine, const Array& errors, const std::vector<std::string>& effects,
         const std::vector<double>& effect_params, const std::vector<double>& b_deg,
         const std::vector<double>& c_deg, const Array& nests, double dwell_s, double noise_um,
         double probe_zero_um, std::optional<Array> probe_dirs, bool write_d, unsigned seed) {
        MachineModel t;
        t.machine = machine;
        t.errors = LocationErrors<double>(vec_of<8>(errors, "errors"));
        t.effects = effects_of(effects);
        t.effect_params = effect_params;
        RtestSimOptions o;
        o.pattern.b_deg = b_deg;
        o.pattern.c_deg = c_deg;
        o.pattern.nests = vectors_of(nests, "nests");
        o.pattern.dwell_s = dwell_s;
        o.noise_um = noise_um;
        o.probe_zero_um = probe_zero_um;
        if (probe_dirs) o.probe_dirs = matrix3_of(*probe_dirs, "probe_dirs");
        o.write_d = write_d;
        o.seed = seed;
        RtestSimulation sim = simulate_rtest(t, o);
        return std::make_pair(std::move(sim.session), rows_from(sim.probe_zeros));
      },
      pyb::arg("machine"), pyb::arg("errors"), pyb::arg("effects"), pyb::arg("effect_params"),
      pyb::arg("b_deg"), pyb::arg("c_deg"), pyb::arg("nests"), pyb::arg("dwell_s"),
      pyb::arg("noise_um"), pyb::arg("probe_zero_um"), pyb::arg("probe_dirs") = std::nullopt,
      pyb::arg("write_d") = true, pyb::arg("seed") = 1u,
      R"doc(Simulate an R-test session (rtest/simulate.hpp).

Parameters
----------
machine : MachineType (any; the pattern must fit its limits: default_rtest_pattern)
errors : (8,) location errors (mm, rad)
effects, effect_params : catalogue ids and their parameters back to back
b_deg, c_deg : the grid, tilt axis outer and rotary axis inner (deg)
nests : (K, 3) nominal ball centres, table frame (mm)
dwell_s : time between readings (s)
noise_um, probe_zero_um : 1-sigma reading noise and per-set-up probe zero (um)
probe_dirs : (3, 3) rows = probe directions: raw d1,d2,d3 are written as well
write_d : with probe_dirs, also write dx,dy,dz

Returns
-------
(session, probe_zeros (K, 3) mm))doc");
  m.def(
      "rtest_readings",
      [](MachineType machine, const Array& errors, const std::vector<std::string>& effects,
         const std::vector<double>& effect_params, const Array& q, const Array& angles,
         const Eigen::VectorXd& time, std::optional<Array> linear_reference) {
        MachineModel t;
        t.machine = machine;
        t.errors = LocationErrors<double>(vec_of<8>(errors, "errors"));
        t.effects = effects_of(effects);
        t.effect_params = effect_params;
        if (static_cast<int>(t.effect_params.size()) != t.effects.num_params())
          throw InvalidArgument("effect_params: expected " +
                                std::to_string(t.effects.num_params()) + " values");
        const Eigen::Vector3d qv = vec_of<3>(q, "q");
        const auto a = rows_of<2>(angles, "angles");
        if (time.size() != a.rows()) throw InvalidArgument("time: one value per row of angles");
        std::vector<RotaryAngles<double>> poses;
        for (Eigen::Index i = 0; i < a.rows(); ++i) poses.push_back({a(i, 0), a(i, 1)});
        if (linear_reference)
          t.effects.linear_reference = vec_of<3>(*linear_reference, "linear_reference");
        return rows_from(rtest_readings(
            t, qv, poses, std::vector<double>(time.data(), time.data() + time.size())));
      },
      pyb::arg("machine"), pyb::arg("errors"), pyb::arg("effects"), pyb::arg("effect_params"),
      pyb::arg("q"), pyb::arg("angles"), pyb::arg("time"),
      pyb::arg("linear_reference") = std::nullopt,
      "Noise-free readings (N, 3) of the nest at q (mm) at angles (N, 2) in rad and time (N,) s, "
      "no probe zero: the simulator's truth. linear_reference (3,) mm: the session's mean "
      "commanded "
      "xyz, about which the linear-axis polynomials are taken (None: the mean of these poses).");
}

// The device's calibration (Sec. 3.1-3.2): probe directions and the sphere's offset.
void bind_rtest_device(pyb::module_& m) {
  pyb::class_<ProbeCalibration>(m, "ProbeCalibration", "Probe directions from linear moves.")
      .def_readonly("dirs", &ProbeCalibration::dirs, "unit directions (rows), table frame")
      .def_readonly("gains", &ProbeCalibration::gains)
      .def_readonly("zeros", &ProbeCalibration::zeros, "probe zero offsets, mm")
      .def_readonly("direction_std_rad", &ProbeCalibration::direction_std_rad)
      .def_readonly("gain_std", &ProbeCalibration::gain_std)
      .def_property_readonly("residuals",
                             [](const ProbeCalibration& c) { return rows_from(c.residuals); })
      .def_readonly("residual_rms_um", &ProbeCalibration::residual_rms_um)
      .def_readonly("sigma_um", &ProbeCalibration::sigma_um);
  pyb::class_<SphereOffsetCalibration>(m, "SphereOffsetCalibration",
                                       "Sphere offset from the spindle axis.")
      .def_readonly("offset", &SphereOffsetCalibration::offset, "(x, y) at spindle angle 0, mm")
      .def_readonly("offset_std", &SphereOffsetCalibration::offset_std)
      .def_readonly("centre", &SphereOffsetCalibration::centre)
      .def_readonly("residual_rms_um", &SphereOffsetCalibration::residual_rms_um);

  m.def(
      "calibrate_probe_directions",
      [](const Array& moves, const Array& readings) {
        const auto mv = rows_of<3>(moves, "moves");
        const auto rd = rows_of<3>(readings, "readings");
        if (mv.rows() != rd.rows()) throw InvalidArgument("readings: one row per move");
        std::vector<ProbeCalibrationSample> s(static_cast<std::size_t>(mv.rows()));
        for (Eigen::Index i = 0; i < mv.rows(); ++i)
          s[static_cast<std::size_t>(i)] = {mv.row(i).transpose(), rd.row(i).transpose()};
        return calibrate_probe_directions(s);
      },
      pyb::arg("moves"), pyb::arg("readings"),
      "Probe directions, gains and zeros from commanded moves (N, 3) and readings (N, 3), mm.");
  m.def(
      "simulate_probe_calibration",
      [](const Array& dirs, const Array& zeros, const Array& moves, double noise_um,
         unsigned seed) {
        Rows3 r;
        const auto s =
            simulate_probe_calibration(matrix3_of(dirs, "dirs"), vec_of<3>(zeros, "zeros"),
                                       vectors_of(moves, "moves"), noise_um, seed);
        r.resize(static_cast<Eigen::Index>(s.size()), 3);
        for (std::size_t i = 0; i < s.size(); ++i)
          r.row(static_cast<Eigen::Index>(i)) = s[i].readings.transpose();
        return r;
      },
      pyb::arg("dirs"), pyb::arg("zeros"), pyb::arg("moves"), pyb::arg("noise_um"),
      pyb::arg("seed"), "Simulated readings (N, 3) of the direction calibration.");
  m.def(
      "default_calibration_moves",
      [](double step_mm) { return rows_from(default_calibration_moves(step_mm)); },
      pyb::arg("step_mm") = 0.5, "+-step along X, Y, Z and the 4 body diagonals (14, 3), mm.");
  m.def(
      "calibrate_sphere_offset",
      [](const Array& dirs, const Eigen::VectorXd& angles, const Array& readings) {
        const auto rd = rows_of<3>(readings, "readings");
        if (rd.rows() != angles.size()) throw InvalidArgument("readings: one row per angle");
        std::vector<SpindleIndexSample> s(static_cast<std::size_t>(rd.rows()));
        for (Eigen::Index i = 0; i < rd.rows(); ++i)
          s[static_cast<std::size_t>(i)] = {angles[i], rd.row(i).transpose()};
        return calibrate_sphere_offset(matrix3_of(dirs, "dirs"), s);
      },
      pyb::arg("dirs"), pyb::arg("angles"), pyb::arg("readings"),
      "Sphere offset from spindle indexing: angles (N,) rad, readings (N, 3) mm.");
  m.def(
      "simulate_spindle_indexing",
      [](const Array& dirs, const Array& zeros, const Array& offset, const Array& centre,
         const std::vector<double>& angles, double noise_um, unsigned seed) {
        const auto s = simulate_spindle_indexing(
            matrix3_of(dirs, "dirs"), vec_of<3>(zeros, "zeros"), vec_of<2>(offset, "offset"),
            vec_of<3>(centre, "centre"), angles, noise_um, seed);
        Rows3 r(static_cast<Eigen::Index>(s.size()), 3);
        for (std::size_t i = 0; i < s.size(); ++i)
          r.row(static_cast<Eigen::Index>(i)) = s[i].readings.transpose();
        return r;
      },
      pyb::arg("dirs"), pyb::arg("zeros"), pyb::arg("offset"), pyb::arg("centre"),
      pyb::arg("angles"), pyb::arg("noise_um"), pyb::arg("seed"),
      "Simulated spindle-indexing readings (N, 3), mm.");
  m.def(
      "displacements_from_raw",
      [](const RtestSession& s, std::optional<Array> dirs) {
        return dirs ? displacements_from_raw(s, matrix3_of(*dirs, "dirs"))
                    : displacements_from_raw(s);
      },
      pyb::arg("session"), pyb::arg("dirs") = std::nullopt,
      "Fill dx,dy,dz from raw d1,d2,d3 with the session's probe.N.dir, or with calibrated dirs "
      "(3, 3) (rows keep a dx,dy,dz they already have).");
  m.def(
      "compensate_sphere_offset",
      [](const RtestSession& s, const Array& offset) {
        return compensate_sphere_offset(s, vec_of<2>(offset, "offset"));
      },
      pyb::arg("session"), pyb::arg("offset"),
      "The session with the sphere's offset (x, y) from the spindle axis taken out of every d.");
}

}  // namespace

void bind_rtest(pyb::module_& m) {
  bind_rtest_basis(m);
  bind_rtest_joint_model(m);
  bind_rtest_identification(m);
  bind_rtest_prediction(m);
  bind_rtest_simulation(m);
  bind_rtest_device(m);
}

}  // namespace rotacal::py
