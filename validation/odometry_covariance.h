#pragma once
// An honest odometry covariance for a robot's EKF (robot_localization, Nav2), from the errors of
// the calibrated odometry on runs the calibration did not train on (docs/ros2.md derives it).
//
// Twist. Each held-out run is cut into consecutive windows of `window_s` of encoder time. In a
// window from t0 to t1 the odometry replays from the ground-truth pose at t0; its error is the
// pose difference at t1 in the robot frame at t0,
//   e = R(-theta_gt(t0)) (p_odo(t1) - p_gt(t1)),   e_theta = wrap(theta_odo(t1) - theta_gt(t1)),
// and the error of the mean body twist over the window is (e_x, e_y, e_theta) / (t1 - t0). The
// twist variance per axis is the mean square of that over every window (vx, vy in m^2/s^2,
// omega in rad^2/s^2): the variance of the twist the odometry reports, averaged over window_s.
//
// Pose. The final pose error of each held-out run, in the robot frame at its start (Palacin
// Eq. 14's residual), grows with the path: its variance per metre travelled is the mean over the
// runs of e_i^2 / d, d the run's odometry path length (m), per axis (m^2/m for x and y, rad^2/m
// for the heading): the covariance after d metres is d times it (a random walk in distance).
//
// Both include the ground truth's own noise (it cannot be told apart from the odometry's here):
// they err on the side of a larger covariance.

#include <array>
#include <cstddef>
#include <vector>

#include "models/model_interface.h"
#include "odometry/run_log.h"

namespace fitcal {

// The errors the covariance is made of, kept apart so that one set can estimate it and another
// check it (OdometryCoverage).
struct OdometryErrors {
  std::vector<std::array<double, 3>> twist;  // per window: vx (m/s), vy (m/s), omega (rad/s)
  std::vector<std::array<double, 3>> pose;   // per run: x (m), y (m), theta (rad), start frame
  std::vector<double> path_m;                // per run: odometry path length (m)
};

struct OdometryCovariance {
  std::array<double, 3> twist_variance{};        // m^2/s^2, m^2/s^2, rad^2/s^2
  std::array<double, 3> pose_variance_per_m{};   // m^2/m, m^2/m, rad^2/m
  double window_s = 1.0;
  std::size_t windows = 0, runs = 0;
};

// Replays every run with the model at p. Runs shorter than one window add no twist error; a run
// whose odometry path is shorter than 1 cm adds no pose error (nothing travelled to scale by).
OdometryErrors CollectOdometryErrors(const RobotModelInterface& model,
                                     const std::vector<double>& p,
                                     const std::vector<RunLog>& runs, double window_s = 1.0);

// Mean squares as above; zeros where there are no errors.
OdometryCovariance EstimateOdometryCovariance(const OdometryErrors& errors, double window_s);

// The share of errors (every axis of every window or run) inside k sigma of `covariance`
// (sigma of a run's pose error: sqrt(variance per metre x its path)); near 0.683 and 0.954 for
// k = 1, 2 when the errors are Gaussian and the covariance right.
struct OdometryCoverage {
  double twist_within_1_sigma = 0.0, twist_within_2_sigma = 0.0;
  double pose_within_1_sigma = 0.0, pose_within_2_sigma = 0.0;
  std::size_t twist_samples = 0, pose_samples = 0;
};
OdometryCoverage CoverageOf(const OdometryCovariance& covariance, const OdometryErrors& errors);

}  // namespace fitcal
