#pragma once
// An odometry covariance a robot's EKF (robot_localization, Nav2) can trust, from the errors of
// the calibrated odometry on runs the calibration did not train on (docs/ros2.md derives it).
//
// The controller publishes its twist on every message: the twist over one publish interval
// (`interval_s`: the controller's publish period, or the encoder period), and its pose as a
// constant covariance. The errors against the ground truth hold two things: the odometry's own
// error and the ground truth's noise. The latter does not grow with the window; the former does.
//
// Structure function. Each held-out run is cut into non-overlapping windows of L encoder samples
// for L = 1, 2, 4, ..., 256, of at least two ground-truth intervals (shorter ones read the ground
// truth between the same samples at both ends, where its noise cancels). In a window [t0, t1] the
// odometry's displacement, replayed from the identity, is compared with the ground truth's,
// expressed in its frame at t0 (its heading there averaged over +-kHeadingSmoothingS, so the ground
// truth's heading noise does not rotate the displacement); the mean square error per axis against
// the window's duration T is fitted by
//   V(T) = c + beta T + alpha T^2,   c, beta, alpha >= 0,
// where c is what does not grow with T: twice the ground truth's noise variance plus the encoder
// quantisation (a tick's uncertainty at either end, known from the robot's encoder ticks; zero for
// encoders logged as rates), beta T an error white in time (rate noise) and alpha T^2 one that
// stays put over the windows (slip, calibration error). The ground truth's noise,
// (c - quantisation) / 2, is removed: the twist variance per message is
//   (beta dt + alpha dt^2 + quantisation) / dt^2,   dt = interval_s.
//
// Pose. The same errors over windows of odometry path d = 0.25, 0.5, 1, 2, 4 m, the ground
// truth's noise (2 x its variance) removed, are fitted per axis by the law the data show,
//   V(d) = a d^p   (least squares in log V against log d),
// and the controller's constant is V(1 m) = a. Dead reckoning's heading error is a random walk in
// distance (p near 1), its position error grows faster (the heading error rotates what follows:
// p up to 3): a per-metre law would make position too wide at 1 m. A negative p is taken as 0.
// A twist axis with no growth resolved gets the growth its windows could hide (an upper bound,
// `twist_unresolved`), never 0; so does a pose axis (`pose_unresolved`).

#include <array>
#include <cstddef>
#include <vector>

#include "models/model_interface.h"
#include "odometry/run_log.h"

namespace fitcal {

struct OdometryCovariance {
  double interval_s = 0.0;                       // the twist's interval (one message)
  std::array<double, 3> twist_variance{};        // per message: m^2/s^2, m^2/s^2, rad^2/s^2
  std::array<double, 3> pose_variance_1m{};      // after 1 m of path: m^2, m^2, rad^2
  std::array<double, 3> pose_growth_exponent{};  // p of V(d) = V(1 m) d^p
  // The ground truth's own noise variance found and removed (m^2, m^2, rad^2), and the encoder
  // quantisation's part of a window's error (same units).
  std::array<double, 3> ground_truth_variance{};
  std::array<double, 3> quantisation_variance{};
  // Axes whose twist error the windows did not resolve above the ground truth's noise: their
  // twist variance is the bound the windows set (what they could hide), not a measurement.
  std::array<bool, 3> twist_unresolved{};
  // The same for the pose after 1 m: the bound the path windows set.
  std::array<bool, 3> pose_unresolved{};
  std::size_t windows = 0, runs = 0;
};

// Estimates it from `runs` replayed with the model at p; interval_s <= 0 takes the median encoder
// interval. Zeros where the runs hold no windows.
OdometryCovariance EstimateOdometryCovariance(const RobotModelInterface& model,
                                              const std::vector<double>& p,
                                              const std::vector<RunLog>& runs, double interval_s);

// V(T) = c + beta T + alpha T^2 fitted to mean squares `v` at durations `t` with weights `w`,
// every coefficient >= 0 (the best of the non-negative subsets): {c, beta, alpha}.
std::array<double, 3> FitStructureFunction(const std::vector<double>& t,
                                           const std::vector<double>& v,
                                           const std::vector<double>& w);

}  // namespace fitcal
