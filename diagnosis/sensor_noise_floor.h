#pragma once
// The noise floor from the data's own physics: what the sensors alone put on a fitted model's
// residual, estimated from the residual track's high frequencies, so that a run's residual can be
// judged without repetitions of it (free driving has none) and the scatter between repetitions
// can itself be judged (an effect that changes from one repetition to the next lands in it).
//
// Model of the residual track r_j (replay - ground truth at ground-truth sample j, replay started
// at sample 0's ground-truth pose), two independent processes (to first order in the errors):
//   - the ground truth's measurement noise n_j, white, variance s^2 per component: it enters
//     every r_j once (with the opposite sign) and the start pose once (r_0 = 0);
//   - the odometry's own noise (encoder quantisation and rate noise, random wheel slip), a random
//     walk: body-frame increments w_k per interval of a grid of ground-truth samples at least
//     0.2 s apart (kMinIntervalS in the .cc says why), variance q^2 per component (x, y, theta),
//     each turned into the world by the heading of its interval, and each heading increment carried
//     to position by the lever arm to every later sample.
// The body-frame increments of the residual, u_k = R(theta_k-1)^T (dr_xy - e_theta J dg_xy) and
// u_theta = dr_theta (dg the ground truth's step, J a quarter turn: the first term removes what an
// existing heading error does to the step), are then w_k + n_k - n_k-1 + (the systematic part,
// smooth and small per interval), whose autocovariance at lags 0 and 1 is
//   gamma_0 = q^2 + 2 s^2,   gamma_1 = -s^2
// (an MA(1) plus white noise: the Allan-variance argument of IEEE Std 952 for a white phase noise
// and a random walk, at the shortest lag). Pooled over every interval of every run (a few
// intervals per run cannot estimate a variance), s^2 = max(0, -gamma_1), q^2 = max(0, gamma_0 -
// 2 s^2). A systematic residual that is smooth adds about equally to gamma_0 and gamma_1, so it
// raises q^2 and lowers s^2 by about its variance per interval: on a badly fitted model the floor
// is too high (the test below loses power), never too low.
//
// Propagated to a run's error at given times (interpolated between samples, as the lack-of-fit
// components are), in the run's start frame, the two processes give each run its own 3T x 3T
// covariance (T times) - long runs and large turns get larger floors, as they should.
//
// The test (TestAgainstSensorFloor): every run's lack-of-fit components e_i, whitened by their
// covariance, after the linearised refit of every fitted parameter on all runs:
//   chi2 = min_delta sum_i |L_i^-1 (e_i - J_i delta)|^2,  df = 3T N - (identifiable parameters),
// p = P(chi2(df) > chi2). Where runs repeat a trajectory, their scatter around the set's mean is
// checked against the same floor: sum (e - mean)^T Sigma^-1 (e - mean) on 3T sum (m - 1) df; a
// ratio near 1 says the floor and the repetitions agree, well above 1 that the runs differ by more
// than the sensors' noise (random slip beyond the walk model, or an effect that changes from run to
// run). Limits, stated: ground-truth noise correlated over samples, or odometry noise correlated
// over many intervals, is not white/walk; the repetition check is there to show it.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "fit/effect_fit.h"

namespace fitcal {

struct SensorNoise {
  bool available = false;  // needs a few intervals (kMinIntervals in the .cc)
  int num_intervals = 0;   // of the walk's grid, over all runs
  // Per component x, y (body frame) and theta: the ground truth's white noise s^2 (m^2, rad^2)
  // and the odometry's random walk q^2 per interval of the walk's grid (header).
  std::array<double, 3> ground_truth_var{};
  std::array<double, 3> walk_var_per_interval{};
};

// Pooled over the tracks (every ground-truth sample's error, as ComputeTrackErrors gives them).
SensorNoise EstimateSensorNoise(const std::vector<TrackErrors>& tracks);

// The covariance of a run's errors at `times` (x, y, theta each, 3 times.size() rows), in the
// frame turned by theta0 (the run's start frame), under the noise above.
Eigen::MatrixXd PropagateSensorNoise(const SensorNoise& noise, const TrackErrors& track,
                                     const std::vector<double>& times, double theta0);

struct SensorFloorTest {
  bool available = false;
  double chi2 = 0.0, df = 0.0;
  double ratio = 0.0;  // chi2 / df: how many times the floor the residual is
  double p_value = 1.0;
  // The scatter between repetitions against the floor.
  bool has_repetition_check = false;
  double repetition_ratio = 0.0, repetition_df = 0.0;
  double repetition_p_above = 1.0;  // P(chi2 >= observed): the runs differ more than the noise
};

// A linearised refit of parameters on whitened residuals z with whitened derivatives Jz, given
// normal = sum Jz^T Jz and rhs = sum Jz^T z: the part of sum |z|^2 it removes. Directions whose
// eigenvalue is below 1e-10 of the largest are not fitted; `identifiable` counts the others.
double ExplainedByLinearisedRefit(const Eigen::MatrixXd& normal, const Eigen::VectorXd& rhs,
                                  int* identifiable);

// e[i]: run i's components; jacobian[i]: their derivatives with respect to every fitted parameter;
// covariance[i]: PropagateSensorNoise's; group[i]: the runs it repeats (RunFeatures::
// repetition_group).
SensorFloorTest TestAgainstSensorFloor(const std::vector<Eigen::VectorXd>& e,
                                       const std::vector<Eigen::MatrixXd>& jacobian,
                                       const std::vector<Eigen::MatrixXd>& covariance,
                                       const std::vector<std::string>& group);

// Two or three lines for the diagnose report: the noise estimated, the residual against it, the
// repetitions against it.
std::string FormatSensorFloor(const SensorNoise& noise, const SensorFloorTest& test);
// One line for a residual significantly above the floor, saying whether the repetitions show it
// as varying between runs.
std::string SensorFloorFinding(const SensorFloorTest& test);

}  // namespace fitcal
