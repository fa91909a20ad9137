#pragma once
// Calibration trajectories of a differential drive for the generic simulator (model_simulator.h):
// Borenstein & Feng's UMBmark squares, both directions, and circles of several radii, both
// directions. Labels carry the shape ("square-cw", "circle-ccw-r0.50"): ClosedForms picks the
// UMBmark squares by the word "square".

#include <vector>

#include "models/trajectory_spec.h"

namespace fitcal::sim {

// At rest before and after every corner of a square (as UMBmark stops).
inline constexpr double kUmbmarkPauseS = 0.6;

struct DiffDriveTrajectoryOptions {
  double square_side_m = 1.0;  // Borenstein & Feng used 4 m; OptiOdom 0.75 and 1.7 m
  double speed_m_s = 0.2;
  double turn_rate_rad_s = 0.6;  // on the spot, at the square's corners
  std::vector<double> circle_radii_m = {0.5, 1.0};
  double circle_laps = 1.0;  // < 1 or non-integer: an open arc (its end pose sees the scale)
};

// One lap of a square of side L: L straight, stop, turn 90 deg on the spot (left for CCW, right
// for CW), stop; four times, so the robot ends at its start, heading as at the start.
TrajectorySpec UmbmarkSquare(bool clockwise, int repetition,
                             const DiffDriveTrajectoryOptions& options = {});

// circle_laps laps of a circle of radius r at speed_m_s (left for CCW).
TrajectorySpec CircleTrajectory(double radius_m, bool clockwise, int repetition,
                                const DiffDriveTrajectoryOptions& options = {});

// Every square (CW, CCW) and circle (each radius, CW and CCW) for repetitions 1..repetitions,
// ordered by repetition, then trajectory.
std::vector<TrajectorySpec> DiffDriveCalibrationTrajectories(
    int repetitions, const DiffDriveTrajectoryOptions& options = {});

}  // namespace fitcal::sim
