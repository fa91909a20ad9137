#include "models/omni/omni_trajectories.h"

#include <utility>

#include "models/omni/flower_trajectories.h"

namespace fitcal::sim {

namespace {

TrajectorySpec Spin(bool clockwise, int repetition, const OmniTrajectoryOptions& options) {
  TrajectorySpec spec;
  spec.label = clockwise ? "S-cw" : "S-ccw";
  spec.repetition = repetition;
  const double omega = (clockwise ? -1.0 : 1.0) * options.spin_rate_rad_s;
  spec.segments.push_back({{0.0, 0.0, omega}, options.spin_angle_rad / options.spin_rate_rad_s});
  return spec;
}

}  // namespace

std::vector<TrajectorySpec> OmniFlowerTrajectories(int repetitions,
                                                   const OmniTrajectoryOptions& options) {
  const std::vector<MotionCommand> flower = FlowerTrajectories(
      options.speed_m_s, options.omega_abs_rad_s, options.distance_m, options.num_directions);
  std::vector<TrajectorySpec> out;
  for (int rep = 1; rep <= repetitions; ++rep) {
    for (TrajectorySpec& spec : FlowerSpecs(flower, 1)) {
      spec.repetition = rep;
      out.push_back(std::move(spec));
    }
    if (options.spin_angle_rad > 0.0) {
      out.push_back(Spin(false, rep, options));
      out.push_back(Spin(true, rep, options));
    }
  }
  return out;
}

}  // namespace fitcal::sim
