#include "rotacal/ballbar/timeline.hpp"

#include <algorithm>

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
}

BallbarSample ProgramTimeline::at(double t) const {
  if (!(t >= points_.front().time)) return points_.front();
  if (t >= points_.back().time) return points_.back();
  // First point with time > t; the bracket is [i-1, i].
  const auto it = std::upper_bound(points_.begin(), points_.end(), t,
                                   [](double v, const BallbarSample& s) { return v < s.time; });
  const std::size_t i = static_cast<std::size_t>(it - points_.begin());
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
  const bool same_test = b.test != "transition" && (segment_[i - 1] == segment_[i] ||
                                                    (segment_[i - 1] + 1 == segment_[i] && a.test != "transition"));
  s.test = w == 0.0 ? a.test : same_test ? b.test : "transition";
  return s;
}

}  // namespace rotacal
