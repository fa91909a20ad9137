#include "models/diff_drive/diff_drive_trajectories.h"

#include <cmath>

#include "odometry/text_format.h"

namespace fitcal::sim {

TrajectorySpec UmbmarkSquare(bool clockwise, int repetition,
                             const DiffDriveTrajectoryOptions& options) {
  TrajectorySpec spec;
  spec.label = clockwise ? "square-cw" : "square-ccw";
  spec.repetition = repetition;
  const double turn = clockwise ? -options.turn_rate_rad_s : options.turn_rate_rad_s;
  for (int corner = 0; corner < 4; ++corner) {
    spec.segments.push_back(
        {{options.speed_m_s, 0.0, 0.0}, options.square_side_m / options.speed_m_s});
    spec.segments.push_back({{}, kUmbmarkPauseS});
    spec.segments.push_back({{0.0, 0.0, turn}, 0.5 * M_PI / options.turn_rate_rad_s});
    spec.segments.push_back({{}, kUmbmarkPauseS});
  }
  spec.segments.pop_back();  // the run's rest_after_s ends it
  return spec;
}

TrajectorySpec CircleTrajectory(double radius_m, bool clockwise, int repetition,
                                const DiffDriveTrajectoryOptions& options) {
  TrajectorySpec spec;
  spec.label = StrFormat("circle-%s-r%.2f", clockwise ? "cw" : "ccw", radius_m);
  spec.repetition = repetition;
  const double omega = (clockwise ? -1.0 : 1.0) * options.speed_m_s / radius_m;
  const double duration_s = options.circle_laps * 2.0 * M_PI * radius_m / options.speed_m_s;
  spec.segments.push_back({{options.speed_m_s, 0.0, omega}, duration_s});
  return spec;
}

std::vector<TrajectorySpec> DiffDriveCalibrationTrajectories(
    int repetitions, const DiffDriveTrajectoryOptions& options) {
  std::vector<TrajectorySpec> out;
  for (int rep = 1; rep <= repetitions; ++rep) {
    out.push_back(UmbmarkSquare(true, rep, options));
    out.push_back(UmbmarkSquare(false, rep, options));
    for (double r : options.circle_radii_m) {
      out.push_back(CircleTrajectory(r, true, rep, options));
      out.push_back(CircleTrajectory(r, false, rep, options));
    }
  }
  return out;
}

}  // namespace fitcal::sim
