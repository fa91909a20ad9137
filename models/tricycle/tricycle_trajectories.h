#pragma once
// Calibration trajectories for a tricycle (models/tricycle/), as twist segments for the generic
// simulator (sim/model_simulator.h):
//
//   circle_<dir>_<deg>  kCircleTurns turns (1.25) at a constant steering angle
//                       phi' = deg, counter-clockwise (ccw, phi' > 0) and clockwise (cw), for each
//                       angle of steering_deg: forward speed v and yaw rate
//                       omega = v tan(phi') / L, so the rear axle's centre traces the arc of
//                       radius L / tan(phi') (tricycle_kinematics.h, T2) for 2 pi turns / |omega|;
//   square_<dir>        a square of side square_side_m driven forward at v, with in-place turns
//                       of 90 deg at the corners (steering at +-90 deg, vx = 0, omega = +-rate),
//                       counter-clockwise and clockwise, then its first side once more; with
//                       max_steering_deg below 90 the corners are quarter arcs at that steering.
// Circles at several steering angles both ways separate the wheelbase from the steering offset
// (one angle in one direction sees only sin(phi + phi_0) / L); straight legs and in-place turns
// separate the wheel radius (distance) from the wheelbase (turn per distance).
//
// The paths are open on purpose. A closed path (a whole number of circles, a square back at its
// corner) ends where it started for ANY common scale of r and L: the heading sees r / L only, and
// the shape scales with L (circle radius L / tan phi') or r (straight sides), so the final pose
// cannot tell the scale (simulated: sigma of r 7 mm on 2 mm ground-truth noise). Closed circles
// also hide a steering channel of the wrong sign (a clockwise full turn ends where a
// counter-clockwise one does). An extra quarter circle, an extra side, put the end a path-sized
// distance away from the start.

#include <vector>

#include "models/trajectory_spec.h"

namespace fitcal::sim {

inline constexpr double kCircleTurns = 1.25;  // not a whole number: see "open on purpose" above

struct TricycleTrajectoryOptions {
  double wheelbase_m = 0.15;  // the L used to turn steering angles into yaw rates (nominal)
  double speed_m_s = 0.1;     // forward speed of the rear axle's centre
  std::vector<double> steering_deg = {10.0, 20.0, 30.0, 45.0};  // circles, each both ways
  double square_side_m = 1.0;
  double turn_rate_rad_s = 0.4;  // in-place turns at the square's corners
  // The largest steering angle the robot can drive and read (0, 90] deg. Below 90 the square's
  // corners are quarter arcs at this steering instead of turns in place (a column read through a
  // gain below 1 cannot report 90 deg: TricycleReadableSteeringDeg).
  double max_steering_deg = 90.0;
  // A corner's arc lasts at least this long: two of the simulator's 0.4 s ramps of the commanded
  // twist (sim/model_simulator.cc refuses a segment shorter than one). Near 90 deg the arc turns
  // faster, so such a corner steers less than max_steering_deg.
  double min_corner_s = 0.8;
  int repetitions = 1;           // each trajectory this many times (repetition 1..n)

  // Empty when valid, else what is wrong.
  std::string Check() const;
};

// Repetition 1 of every trajectory (circles in steering_deg order, ccw then cw for each, then the
// ccw and the cw square), then repetition 2, ... up to `repetitions`. Throws std::invalid_argument
// for invalid options.
std::vector<TrajectorySpec> TricycleTrajectories(const TricycleTrajectoryOptions& options = {});

// The largest wheel steering angle (deg, at most 90) whose column reading an absolute encoder can
// still hold: the column reads (phi - offset) / gain within (-180, 180] deg, kept 20 deg inside
// that for the reading's noise. 90 for a gain of 0.56 or more at zero offset.
double TricycleReadableSteeringDeg(double steering_gain, double steering_offset_rad);

}  // namespace fitcal::sim
