#pragma once
// Palacin et al. 2022's "flower" calibration trajectories (Fig. 9, Table A1;
// models/omni/flower_trajectories.h, which defines them) for any holonomic robot and the generic
// simulator (model_simulator.h): the R, G and B families in n directions of the robot frame, each
// run as one twist segment (FlowerSpecs). With n = 12 and the defaults these are Table A1's 36
// trajectories. Optional spins on the spot (S-ccw, S-cw) excite the yaw alone.

#include <vector>

#include "models/trajectory_spec.h"

namespace fitcal::sim {

struct OmniTrajectoryOptions {
  int num_directions = 12;
  double speed_m_s = 0.35;
  double omega_abs_rad_s = 0.35;  // of the curves
  double distance_m = 1.0;
  double spin_angle_rad = 0.0;  // > 0: add a CCW and a CW spin on the spot of this angle
  double spin_rate_rad_s = 0.7;
};

// The flower (R, G, B families in that order, each in direction order), then the spins, for
// repetitions 1..repetitions (ordered by repetition, then trajectory).
std::vector<TrajectorySpec> OmniFlowerTrajectories(int repetitions,
                                                   const OmniTrajectoryOptions& options = {});

}  // namespace fitcal::sim
