// SPDX-License-Identifier: BSD-3-Clause
// Wording of ambiguities: which test of the standard set-up separates two candidates that
// explain this session's residuals equally well.
#include <Eigen/SVD>
#include <algorithm>
#include <map>
#include <set>
#include <sstream>

#include "rotacal/diagnose/multi_session.hpp"
#include "scoring.hpp"

namespace rotacal::diagnosis_detail {

namespace {

// Several sessions: the design command of each instrument among them, after one of its own
// sessions (the design reads one session). A machine effect is shared by every session of the
// machine, so a test of any of them may decide.
std::string several_sessions_design(const MultiDiagnosisProblem& M, const std::string& pair) {
  std::vector<std::pair<std::string, std::string>> by_instrument;  // instrument, its sessions
  for (std::size_t k = 0; k < M.num_sessions(); ++k) {
    const std::string instrument = M.session(k).problem->instrument(), name = M.session(k).name;
    auto it = std::find_if(by_instrument.begin(), by_instrument.end(),
                           [&](const auto& x) { return x.first == instrument; });
    if (it == by_instrument.end())
      by_instrument.push_back({instrument, name});
    else
      it->second += " or " + name;
  }
  std::string out;
  for (const auto& [instrument, names] : by_instrument)
    out += (out.empty() ? "" : ", or ") + std::string("`rotacal design ") + instrument +
           " --separate " + pair + " --after SESSION` (SESSION: the file of session " + names + ")";
  return out;
}

}  // namespace

std::string separating_test(const DiagnosisProblem& P, const ModelFit& fit, const Score& a,
                            const Score& b, double sigma_mm) {
  // The design command of this session's own instrument (issue 50 item 5: a probe user was told
  // to run `rotacal design ballbar|rtest`), and of each instrument of several sessions.
  const std::string pair = a.effect.id() + "," + b.effect.id();
  const auto* several = dynamic_cast<const MultiDiagnosisProblem*>(&P);
  const std::string design =
      several ? several_sessions_design(*several, pair)
              : "`rotacal design " + P.instrument() + " --separate " + pair + " --after SESSION`";
  if (several)
    return "none of these sessions' tests separates them; " + design +
           " proposes the test that does, or says why none can (a machine effect is shared by "
           "every session of the machine: a test of any of their instruments may decide)";
  if (P.reference_groups().empty())
    return "none of this session's tests separates them; " + design +
           " proposes the test that does, or says why none can";
  // Fit each candidate's full parameter vector to this session's residual, then compare what
  // they predict on the standard test.
  std::vector<std::string> rows_a, rows_b;
  const Eigen::MatrixXd Ra = P.reference_jacobian(fit, a.effect, &rows_a);
  const Eigen::MatrixXd Rb = P.reference_jacobian(fit, b.effect, &rows_b);
  const Eigen::VectorXd diff = Ra * a.params - Rb * b.params;
  // A test this session already holds cannot be the one that separates them: the session's
  // fit saw it and could not tell them apart (there the location errors and the set-up absorb
  // what differs; the raw difference of the two predictions below does not know that).
  const std::set<std::string> held(P.groups().begin(), P.groups().end());
  std::map<std::string, std::pair<double, int>> per;
  for (std::size_t i = 0; i < rows_a.size(); ++i) {
    if (held.count(rows_a[i])) continue;
    auto& acc = per[rows_a[i]];
    acc.first += diff[static_cast<Eigen::Index>(i)] * diff[static_cast<Eigen::Index>(i)];
    acc.second += 1;
  }
  std::string best;
  double best_rms = 0.0;
  for (auto& kv : per) {
    const double r = std::sqrt(kv.second.first / kv.second.second);
    if (r > best_rms) best_rms = r, best = kv.first;
  }
  std::ostringstream out;
  out.precision(2);
  if (best.empty() || best_rms < sigma_mm)
    out << "no test of the standard single set-up that this session lacks separates them (their "
           "predictions differ by less than the noise there); "
        << design << " proposes the smallest added test that does, or says why none can";
  else
    out << "a '" << best << "' test separates them: their predictions differ there by "
        << std::fixed << best_rms * 1e3 << " um RMS";
  return out.str();
}

}  // namespace rotacal::diagnosis_detail
