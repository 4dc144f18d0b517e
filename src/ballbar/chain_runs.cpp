// SPDX-License-Identifier: BSD-3-Clause
// Runs of the measure -> compensate -> measure-again experiment, one or a batch at a time.
#include "rotacal/ballbar/chain_runs.hpp"

#include "rotacal/ballbar/identify_paper.hpp"
#include "rotacal/ballbar/simulate.hpp"
#include "rotacal/core/noise_model.hpp"
#include "rotacal/io/session_arrays.hpp"

namespace rotacal {

namespace {

// The columns of a program that a record keeps, taken once per program.
struct ProgramColumns {
  std::vector<std::string> tests;
  Eigen::VectorXd time;
  std::vector<double> times;  // the same, as noise_gen takes it
  RowMatrix2 angles_deg;
};

ProgramColumns columns_of(const BallbarSession& program) {
  ProgramColumns c;
  c.tests = ballbar_tests(program);
  c.time = ballbar_times(program);
  c.times.assign(c.time.data(), c.time.data() + c.time.size());
  c.angles_deg = ballbar_angles_deg(program);
  return c;
}

BallbarSession record(const BallbarSession& nominal, const RowMatrix3& nominal_xyz,
                      const BallbarSession& program, const ProgramColumns& columns,
                      const BallbarMachineModel& machine, const std::uint64_t* seed,
                      const ChainRunOptions& o) {
  // The exact readings (no noise drawn here, none declared): the noise is AR(1) per test.
  const BallbarSession s = simulate_ballbar(program, machine, {0.0, 1, false});
  Eigen::VectorXd length = ballbar_lengths(s);
  if (seed)
    length += noise_gen::ar1(columns.tests, columns.times, o.noise_rho, o.noise_um * 1e-3, *seed);
  return make_ballbar_session(s.machine, s.ballbar_length, nominal.pivot, columns.tests,
                              columns.time, nominal_xyz, columns.angles_deg, length, o.noise_um);
}

Eigen::Matrix<double, 8, 1> identified_errors(const BallbarSession& s, const ChainRunOptions& o) {
  BallbarIdentification r;
  if (o.method == "paper") {
    r = identify_paper(s, false);
  } else {
    JointFitOptions fit;
    fit.noise.noise = NoiseHandling::automatic;
    r = identify_joint(s, fit);
  }
  Eigen::Matrix<double, 8, 1> e;
  for (int j = 0; j < 8; ++j) e[j] = r.parameters[static_cast<std::size_t>(j)].value;
  return e;
}

void check(const ChainRunOptions& o) {
  if (o.method != "paper" && o.method != "joint")
    throw InvalidArgument("chain runs: method must be 'paper' or 'joint', got '" + o.method + "'");
}

}  // namespace

BallbarSession record_run(const BallbarSession& nominal, const BallbarSession& program,
                          const BallbarMachineModel& machine, std::optional<std::uint64_t> seed,
                          const ChainRunOptions& options) {
  return record(nominal, ballbar_xyz(nominal), program, columns_of(program), machine,
                seed ? &*seed : nullptr, options);
}

LocationErrorRows identify_runs(const BallbarSetup& setup,
                                const std::vector<BallbarMachineModel>& machines,
                                const LocationErrorRows& compensate_for,
                                const std::vector<std::uint64_t>& seeds,
                                const ChainRunOptions& options) {
  check(options);
  const auto n = static_cast<Eigen::Index>(machines.size());
  if (compensate_for.rows() != 0 && compensate_for.rows() != n)
    throw InvalidArgument("identify_runs: compensate_for has " +
                          std::to_string(compensate_for.rows()) + " rows for " + std::to_string(n) +
                          " machines (0 or one per machine)");
  if (!seeds.empty() && static_cast<Eigen::Index>(seeds.size()) != n)
    throw InvalidArgument("identify_runs: " + std::to_string(seeds.size()) + " seeds for " +
                          std::to_string(n) + " machines (none or one per machine)");
  const BallbarSession nominal = commanded_session(plan_ballbar_test(setup));
  const RowMatrix3 nominal_xyz = ballbar_xyz(nominal);
  const ProgramColumns nominal_columns = columns_of(nominal);
  // The program of the last compensated run, kept while the next run is compensated alike.
  BallbarSession program;
  ProgramColumns program_columns;
  LocationErrorRows out(n, 8);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const std::uint64_t* seed = seeds.empty() ? nullptr : &seeds[k];
    BallbarSession s;
    if (compensate_for.rows() == 0) {
      s = record(nominal, nominal_xyz, nominal, nominal_columns, machines[k], seed, options);
    } else {
      if (i == 0 || compensate_for.row(i) != compensate_for.row(i - 1)) {
        const LocationErrors<double> e(
            Eigen::Matrix<double, 8, 1>(compensate_for.row(i).transpose()));
        program = commanded_session(plan_ballbar_test(setup, e));
        program_columns = columns_of(program);
      }
      s = record(nominal, nominal_xyz, program, program_columns, machines[k], seed, options);
    }
    out.row(i) = identified_errors(s, options).transpose();
  }
  return out;
}

}  // namespace rotacal
