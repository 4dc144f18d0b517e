// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/ballbar/timeline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rotacal/core/error.hpp"

namespace rotacal {

ProgramTimeline::ProgramTimeline(const BallbarPlan& plan) {
  header_.machine = plan.setup.machine;
  header_.ballbar_length = plan.setup.ballbar_length;
  header_.pivot = plan.setup.pivot;
  for (std::size_t k = 0; k < plan.segments.size(); ++k) {
    const PlanSegment& seg = plan.segments[k];
    for (const PlannedSample& s : seg.samples) {
      BallbarSample b;
      b.test = seg.kind == SegmentKind::test ? seg.label : "transition";
      b.time = s.time;
      b.xyz = s.xyz;
      b.tilt_deg = s.tilt_deg;
      b.rot_deg = s.rot_deg;
      b.length = plan.setup.ballbar_length;
      points_.push_back(std::move(b));
      segment_.push_back(static_cast<int>(k));
    }
  }
  if (points_.empty()) throw InvalidArgument("ProgramTimeline: the plan has no points");

  const std::size_t n = points_.size();
  block_rate_.assign(n, {});
  block_direction_.assign(n, {});
  const double none = std::numeric_limits<double>::quiet_NaN();
  block_reversal_.assign(n, {none, none});
  RotaryAngles<double> last{0.0, 0.0}, since{none, none};
  for (std::size_t i = 1; i < n; ++i) {
    const double dt = points_[i].time - points_[i - 1].time;
    const RotaryAngles<double> a = points_[i - 1].angles_rad(), b = points_[i].angles_rad();
    RotaryAngles<double> rate{dt > 0.0 ? (b.tilt - a.tilt) / dt : 0.0,
                              dt > 0.0 ? (b.rot - a.rot) / dt : 0.0};
    for (double* r : {&rate.tilt, &rate.rot}) {
      const bool tilt = r == &rate.tilt;
      double& d = tilt ? last.tilt : last.rot;
      double& s = tilt ? since.tilt : since.rot;
      const double sign = *r > 1e-9 ? 1.0 : *r < -1e-9 ? -1.0 : 0.0;
      if (sign != 0.0 && d != 0.0 && sign != d) s = points_[i - 1].time;
      if (sign != 0.0) d = sign;
    }
    block_rate_[i] = rate;
    block_direction_[i] = last;
    block_reversal_[i] = since;
  }
}

std::size_t ProgramTimeline::bracket(double t) const {
  const auto it = std::upper_bound(points_.begin(), points_.end(), t,
                                   [](double v, const BallbarSample& s) { return v < s.time; });
  return static_cast<std::size_t>(it - points_.begin());
}

RotaryMotion ProgramTimeline::motion_at(double t) const {
  RotaryMotion m;
  if (points_.size() < 2 || !(t >= points_.front().time)) return m;
  const std::size_t i = std::min(bracket(t), points_.size() - 1);  // past the end: the last block
  const bool running = t < points_.back().time;
  if (running) m.rate = block_rate_[i];
  m.direction = block_direction_[i];
  const RotaryAngles<double>& r = block_reversal_[i];
  m.since_reversal.tilt = std::isnan(r.tilt) ? m.since_reversal.tilt : t - r.tilt;
  m.since_reversal.rot = std::isnan(r.rot) ? m.since_reversal.rot : t - r.rot;
  return m;
}

BallbarSample ProgramTimeline::at(double t) const {
  if (!(t >= points_.front().time)) return points_.front();
  if (t >= points_.back().time) return points_.back();
  // First point with time > t; the bracket is [i-1, i].
  const std::size_t i = bracket(t);
  const BallbarSample& a = points_[i - 1];
  const BallbarSample& b = points_[i];
  const double dt = b.time - a.time;
  const double w = dt > 0.0 ? (t - a.time) / dt : 0.0;
  BallbarSample s;
  s.time = t;
  s.xyz = a.xyz + w * (b.xyz - a.xyz);
  s.tilt_deg = a.tilt_deg + w * (b.tilt_deg - a.tilt_deg);
  s.rot_deg = a.rot_deg + w * (b.rot_deg - a.rot_deg);
  s.length = header_.ballbar_length;
  // Between two points of one test, or from the end of one run into the next run that
  // continues from it with no transition between (a cw run after its ccw one): that test.
  const bool same_test =
      b.test != "transition" && (segment_[i - 1] == segment_[i] ||
                                 (segment_[i - 1] + 1 == segment_[i] && a.test != "transition"));
  s.test = w == 0.0 ? a.test : same_test ? b.test : "transition";
  return s;
}

}  // namespace rotacal
