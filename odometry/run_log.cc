#include "odometry/run_log.h"

#include <algorithm>
#include <cassert>

namespace fitcal {

Pose2d InterpolateGroundTruth(const GroundTruthTrack& track, double t_s) {
  const auto& t = track.t_s;
  if (t_s <= t.front()) return track.world_T_robot.front();
  if (t_s >= t.back()) return track.world_T_robot.back();
  const std::size_t hi =
      static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), t_s) - t.begin());
  const std::size_t lo = hi - 1;
  const double u = (t_s - t[lo]) / (t[hi] - t[lo]);
  const Pose2d& a = track.world_T_robot[lo];
  const Pose2d& b = track.world_T_robot[hi];
  return Pose2d{a.x + u * (b.x - a.x), a.y + u * (b.y - a.y),
                a.theta + u * WrapAngle(b.theta - a.theta)};
}

}  // namespace fitcal
