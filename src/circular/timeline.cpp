// SPDX-License-Identifier: BSD-3-Clause
#include "rotacal/circular/timeline.hpp"

#include <algorithm>
#include <cmath>

#include "rotacal/core/error.hpp"

namespace rotacal {

CircularTimeline::CircularTimeline(CircularPlanResult plan) : plan_(std::move(plan)) {
  if (plan_.runs.empty()) throw InvalidArgument("CircularTimeline: the plan has no runs");
  header_.machine = plan_.plan.machine;
  header_.ballbar_length = plan_.plan.radius;
  header_.pivot = plan_.plan.centre;
  for (const CircularRun& r : plan_.runs)
    end_.push_back(r.t_start + (r.overshoot_to_deg - r.run_in_from_deg) / r.rate_deg_s);
}

double CircularTimeline::duration() const { return end_.back(); }

CircularTimeline::Position CircularTimeline::position(double t) const {
  t = std::clamp(t, 0.0, duration());
  // The run under way at t, or the next one: the first whose overshoot ends at or after t.
  const std::size_t i =
      static_cast<std::size_t>(std::lower_bound(end_.begin(), end_.end(), t) - end_.begin());
  const CircularRun& r = plan_.runs[std::min(i, plan_.runs.size() - 1)];
  Position p;
  p.run = std::min(i, plan_.runs.size() - 1);
  if (t >= r.t_start) {
    p.on_run = p.moving = true;
    p.angle_deg = r.angle_at(t);
    const double t_data = r.t_start + (r.data_from_deg - r.run_in_from_deg) / r.rate_deg_s;
    const double t_data_end = t_data + (r.data_to_deg - r.data_from_deg) / r.rate_deg_s;
    p.on_data = t >= t_data && t <= t_data_end;
    return p;
  }
  // Before run i: a move along the circle from the previous run's end (same plane), then a
  // 1 s dwell; or, at a new plane, the remount wait at this run's start point.
  p.angle_deg = r.run_in_from_deg;
  if (i == 0 || plan_.runs[i - 1].plane != r.plane) return p;
  const CircularRun& prev = plan_.runs[i - 1];
  const double move = std::remainder(r.run_in_from_deg - prev.overshoot_to_deg, 360.0);
  const double rate = std::abs(r.rate_deg_s);
  const double t_move_end = end_[i - 1] + std::abs(move) / rate;
  if (t < t_move_end) {
    p.moving = true;
    p.angle_deg = prev.overshoot_to_deg + (move >= 0.0 ? 1.0 : -1.0) * rate * (t - end_[i - 1]);
  }
  return p;
}

BallbarSample CircularTimeline::at(double t) const {
  const Position p = position(t);
  const CircularRun& r = plan_.runs[p.run];
  BallbarSample s;
  s.test = p.on_data ? r.label : "transition";
  s.time = t;
  s.xyz =
      circular_point(plan_.plan, r.plane, p.angle_deg) - tool_vector<double>(header_.machine, 0.0);
  s.length = header_.ballbar_length;
  return s;
}

}  // namespace rotacal
