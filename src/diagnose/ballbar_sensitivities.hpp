// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Internal to src/diagnose: the ballbar candidates' Jacobians by the chain rule at the current
// fit (src/ballbar/length_chain.hpp), for a machine without head axes.
//
// dL/dq = sum over places of (dL / d place: the fit's, once per row for every candidate)
//       x (d place / dq: the candidate's own stages alone, by Jets of one effect, at q = 0).
// The second factor does not depend on the fit, so a session keeps it per candidate
// (BallbarPlacesCache) and a later round pays only the sum. test_diagnose_ballbar.cpp checks
// the Jacobians against candidate_jacobian_by_jets for every candidate of the catalogue.

#include <Eigen/Core>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "../ballbar/length_chain.hpp"
#include "rotacal/ballbar/motion.hpp"
#include "rotacal/diagnose/diagnosis.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal::diagnosis_detail {

/// d place / d (each seeded parameter) of one candidate on every row, for the places it enters.
struct BallbarPlaces {
  std::vector<int> places;  ///< length_chain::Place indices, ascending
  int seeds = 0;
  Eigen::MatrixXd d;  ///< column i * seeds + k: d places[i] / d seed k; a row per reading
};

class BallbarSensitivities {
 public:
  /// Machines whose ball pivot goes through every rotary axis (no head axes).
  static bool supports(MachineType m) { return length_chain::supports(m); }
  /// dL / d(each place) on every row of `samples` (with `motion`, one per sample) at fit `at`.
  BallbarSensitivities(MachineType m, const std::vector<BallbarSample>& samples,
                       const std::vector<RotaryMotion>& motion, const ModelFit& at);
  /// Where `effect` (its seeded parameters, at 0) enters each row; what it depends on besides
  /// the rows is in key().
  BallbarPlaces places(const Effect& effect, const std::vector<int>& seed) const;
  std::string key(const Effect& effect, const std::vector<int>& seed) const;
  /// d L / d (the seeded parameters), one column per seed (candidate_jets.hpp's `jets`).
  Eigen::MatrixXd columns(const BallbarPlaces& p) const;

 private:
  template <int N>
  BallbarPlaces places_with(const Effect& effect, const std::vector<int>& seed) const;

  MachineType m_;
  const std::vector<BallbarSample>& samples_;
  const std::vector<RotaryMotion>& motion_;
  std::vector<RotaryAngles<double>> angles_;
  EffectModel reference_;  // no effects: the fit's linear_reference for the candidate's own stages
  Eigen::Matrix<double, Eigen::Dynamic, length_chain::kPlaces>
      s_;  // dL / d place: a column per place
};

/// BallbarPlaces of one session's rows by BallbarSensitivities::key, shared by every fit.
class BallbarPlacesCache {
 public:
  template <typename Make>
  std::shared_ptr<const BallbarPlaces> get(const std::string& key, Make&& make) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = known_.find(key);
      if (it != known_.end()) return it->second;
    }
    auto made = std::make_shared<const BallbarPlaces>(make());
    const auto values = static_cast<std::size_t>(made->d.size());
    std::lock_guard<std::mutex> lock(mutex_);
    if (known_.count(key) || kept_values_ + values > kMaxKeptValues) return made;
    kept_values_ += values;
    return known_.emplace(key, std::move(made)).first->second;
  }

  /// Places are kept up to this many doubles (256 MB: every candidate's of a 90,000-reading
  /// session), beyond that made again when asked: a 1,000,000-reading session's would fill
  /// 1.3 GB (issue 56 bounds a long session at 1 KB a reading). Made or kept, they are equal.
  static constexpr std::size_t kMaxKeptValues = std::size_t{32} << 20;

 private:
  std::mutex mutex_;
  std::size_t kept_values_ = 0;
  std::map<std::string, std::shared_ptr<const BallbarPlaces>> known_;
};

}  // namespace rotacal::diagnosis_detail
