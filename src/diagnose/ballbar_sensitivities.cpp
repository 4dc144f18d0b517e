// SPDX-License-Identifier: BSD-3-Clause
// The ballbar candidates' Jacobians by the chain rule (ballbar_sensitivities.hpp).
#include "ballbar_sensitivities.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "../ballbar/length_chain.hpp"
#include "rotacal/ballbar/problem.hpp"

namespace rotacal::diagnosis_detail {

BallbarSensitivities::BallbarSensitivities(MachineType m, const std::vector<BallbarSample>& samples,
                                           const std::vector<RotaryMotion>& motion,
                                           const ModelFit& at)
    : m_(m),
      samples_(samples),
      motion_(motion),
      s_(static_cast<Eigen::Index>(samples.size()), length_chain::kPlaces) {
  ROTACAL_ASSERT(supports(m) && motion.size() == samples.size());
  reference_.linear_reference = at.effects.linear_reference;
  const BallbarLayout L = ballbar_layout(m, at.effects);
  Eigen::VectorXd x(static_cast<Eigen::Index>(at.parameters.size()));
  for (std::size_t i = 0; i < at.parameters.size(); ++i)
    x[static_cast<Eigen::Index>(i)] = at.parameters[i].value;
  const LocationErrors<double> e(L.errors.of<8>(x));
  const Eigen::Vector3d pivot = L.pivots.of<3>(x);
  const double* p = L.effects.ptr(x.data());
  angles_.reserve(samples.size());
  length_chain::Places s;
  for (std::size_t r = 0; r < samples.size(); ++r) {
    const BallbarSample& smp = samples[r];
    angles_.push_back(smp.angles_rad());
    length_chain::sensitivities(m, e, pivot, at.effects, p,
                                {smp.xyz, angles_.back(), smp.time, motion[r]}, s, nullptr);
    s_.row(static_cast<Eigen::Index>(r)) = s.transpose();
  }
}

BallbarPlaces BallbarSensitivities::places(const Effect& effect,
                                           const std::vector<int>& seed) const {
  ROTACAL_ASSERT(!seed.empty() && seed.size() <= 4 && effect.num_params() <= 4);
  // Most candidates (the harmonic channels among them) seed one parameter: Jets of width 1.
  return seed.size() == 1 ? places_with<1>(effect, seed) : places_with<4>(effect, seed);
}

template <int N>
BallbarPlaces BallbarSensitivities::places_with(const Effect& effect,
                                                const std::vector<int>& seed) const {
  using Jet = ceres::Jet<double, N>;
  using length_chain::kPlaces;
  EffectModel fx = reference_;
  fx.effects = {effect};
  Jet q[4] = {Jet(0.0), Jet(0.0), Jet(0.0), Jet(0.0)};
  for (std::size_t k = 0; k < seed.size(); ++k) q[seed[k]] = Jet(0.0, static_cast<int>(k));
  const Eigen::Index n = s_.rows();
  const int seeds = static_cast<int>(seed.size());
  // Rows in blocks, and a column kept only for a (place, seed) the effect enters: a dense
  // N * kPlaces x n block would hold 864 bytes a row for N = 4 (a long session's peak memory),
  // where the effect enters a few places. The values are the same.
  constexpr Eigen::Index kBlock = 2048;
  Eigen::Matrix<double, N * kPlaces, Eigen::Dynamic> block(N * kPlaces, kBlock);
  Eigen::Matrix<double, kPlaces, N> d;
  std::vector<Eigen::VectorXd> column(static_cast<std::size_t>(kPlaces * seeds));
  for (Eigen::Index r0 = 0; r0 < n; r0 += kBlock) {
    const Eigen::Index rows = std::min(kBlock, n - r0);
    for (Eigen::Index b = 0; b < rows; ++b) {
      const std::size_t i = static_cast<std::size_t>(r0 + b);
      const BallbarSample& smp = samples_[i];
      length_chain::place_derivatives<N>(m_, fx, q, {smp.xyz, angles_[i], smp.time, motion_[i]}, d);
      block.col(b) = Eigen::Map<const Eigen::Matrix<double, N * kPlaces, 1>>(d.data());
    }
    for (int p = 0; p < kPlaces; ++p)
      for (int k = 0; k < seeds; ++k) {
        const auto row = block.row(p + kPlaces * k).head(rows);
        Eigen::VectorXd& c = column[static_cast<std::size_t>(p * seeds + k)];
        if (c.size() == 0 && (row.array() != 0.0).any()) c = Eigen::VectorXd::Zero(n);
        if (c.size()) c.segment(r0, rows) = row.transpose();
      }
  }
  BallbarPlaces out;
  out.seeds = seeds;
  for (int p = 0; p < kPlaces; ++p)
    for (int k = 0; k < seeds; ++k)
      if (column[static_cast<std::size_t>(p * seeds + k)].size()) {
        out.places.push_back(p);
        break;
      }
  out.d = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(out.places.size()) * seeds);
  for (std::size_t i = 0; i < out.places.size(); ++i)
    for (int k = 0; k < seeds; ++k) {
      const Eigen::VectorXd& c = column[static_cast<std::size_t>(out.places[i] * seeds + k)];
      if (c.size()) out.d.col(static_cast<Eigen::Index>(i) * seeds + k) = c;
    }
  return out;
}

std::string BallbarSensitivities::key(const Effect& effect, const std::vector<int>& seed) const {
  std::string k = effect.id();
  for (int s : seed) k += " " + std::to_string(s);
  if (const auto& a = reference_.linear_reference) {
    char buf[80];
    std::snprintf(buf, sizeof buf, " @%.17g,%.17g,%.17g", (*a)[0], (*a)[1], (*a)[2]);
    k += buf;
  }
  return k;
}

Eigen::MatrixXd BallbarSensitivities::columns(const BallbarPlaces& p) const {
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(s_.rows(), p.seeds);
  for (std::size_t i = 0; i < p.places.size(); ++i)
    for (int k = 0; k < p.seeds; ++k)
      out.col(k).array() +=
          s_.col(p.places[i]).array() * p.d.col(static_cast<Eigen::Index>(i) * p.seeds + k).array();
  return out;
}

}  // namespace rotacal::diagnosis_detail
