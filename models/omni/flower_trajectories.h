#pragma once
// The 36 "flower" calibration trajectories of Palacin et al. 2022, Fig. 9 and Table A1: straight
// runs R1..R12, counter-clockwise curves G1..G12 and clockwise curves B1..B12, each a motion
// command held until the robot has covered distance_m: speed v in direction alpha (robot frame,
// alpha = 30 (i - 1) deg for trajectory i) while turning at omega. The same shapes in n
// directions (alpha = 360 (i - 1) / n deg) serve every holonomic robot (omni_trajectories.h).

#include <string>
#include <vector>

#include "models/trajectory_spec.h"

namespace fitcal::sim {

struct MotionCommand {
  std::string label;  // "R1", "G7", ...
  double speed_m_s = 0.0;
  double alpha_rad = 0.0;
  double omega_rad_s = 0.0;
  double distance_m = 0.0;
};

// Table A1 in its printed order (R1..R12, G1..G12, B1..B12); speed_m_s and omega_abs_rad_s let
// the simulator record the same flower at another speed, num_directions in other directions.
std::vector<MotionCommand> FlowerTrajectories(double speed_m_s = 0.35,
                                              double omega_abs_rad_s = 0.35,
                                              double distance_m = 1.0, int num_directions = 12);

// The motion commands as trajectories of one twist segment each (v cos alpha, v sin alpha,
// omega) held for distance / v, for repetitions 1..repetitions (ordered by repetition, then
// command).
std::vector<TrajectorySpec> FlowerSpecs(const std::vector<MotionCommand>& commands,
                                        int repetitions);

}  // namespace fitcal::sim
