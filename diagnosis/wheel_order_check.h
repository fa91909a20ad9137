#pragma once
// RETIRED for every caller but tools/fit_command.cc's omni3 path: the one check of which encoder
// column is which channel is diagnosis/channel_order_check.h (the importers, `fit` and every model
// call it). Delete this file, its .cc and tests/wheel_order_check_test.cc with that path.
//
// Checks, before fitting, that the encoder columns are the wheels the robot YAML says they are,
// and that the rates are in rad/s. The most common silent failure of odometry calibration is a
// swapped or sign-flipped encoder column (wiring, driver config): the fit then "converges" to
// nonsense. A log in degrees/s is the second.
//
// Wheel order and sign (CheckWheelOrder): each of the 3! column orders x 2^3 sign patterns is a
// hypothesis "wheel i's rate is sign_i * column_i". All 48 are scored by the final-pose residual
// sum of squares (SSR, Palacin Eq. 14 residuals, final_pose_residual.h) at the nominal parameters.
// When some other hypothesis beats the recorded order at the nominal, both are fitted (bounded
// Ceres fit, omni3_ceres_fit.h) so that neither is penalised for the nominal being off, and the
// other order is declared "far better" when
//
//     SSR_recorded / SSR_other > F^-1(1 - alpha / 47; d, d),   d = 3 N - 9 (N runs)
//
// i.e. when the ratio exceeds what two models that both explain the data down to Gaussian noise
// would show by chance, with the false-alarm probability alpha spread over the 47 alternatives
// (Bonferroni). With fewer than 4 runs nothing is fitted: the nominal SSRs are compared with d = 3
// N. Hypotheses that the trajectories cannot tell apart (e.g. pure rotations for a symmetric robot)
// score alike and never trigger.
//
// Units (CheckRateUnits): the odometry path length (translation + mean wheel distance x rotation)
// at the nominal parameters against the ground truth's over the same window, pooled over runs.
// A calibration moves wheel radii within their bounds, so a ratio far outside the bound ratios
// (more than 2x beyond) is a unit problem, named when it is near a known factor (deg/s: 180/pi,
// rev/s: 1/(2 pi), rpm: 30/pi).

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "diagnosis/channel_order_check.h"
#include "fit/final_pose_residual.h"
#include "odometry/aligned_run.h"
#include "odometry/parallel_for.h"
#include "odometry/robot_description.h"
#include "odometry/run_log.h"

namespace fitcal {

// wheel i's rate = sign[i] * recorded column[i].
struct WheelMapping {
  std::array<int, 3> column{0, 1, 2};
  std::array<int, 3> sign{1, 1, 1};
  bool IsIdentity() const {
    return column == std::array<int, 3>{0, 1, 2} && sign == std::array<int, 3>{1, 1, 1};
  }
};

// All 48 mappings, the identity first.
std::vector<WheelMapping> AllWheelMappings();

// Copies of the runs with the mapping applied to every sample.
std::vector<AlignedRun> ApplyWheelMapping(const std::vector<AlignedRun>& runs,
                                          const WheelMapping& mapping);

// Words for a mapping against the recorded columns w_a, w_b, w_c, e.g.
// "columns w_a and w_b swapped" or "wheel c = -w_c (sign flipped)".
std::string DescribeWheelMapping(const WheelMapping& mapping);

struct WheelOrderOptions {
  ResidualWeights weights;                // as the fit's
  double false_alarm_probability = 1e-6;  // alpha above
  double segment_length_m = 0.5;          // windows of CheckWheelOrderOnSegments
  int num_threads = 0;
  bool IsValid(std::string* error) const;
};

struct WheelOrderReport : MiswiringScores {
  WheelMapping best;  // the best-scoring mapping (identity when not miswired)
};

// Throws std::invalid_argument for invalid options or no runs.
WheelOrderReport CheckWheelOrder(const std::vector<AlignedRun>& runs, const Omni3Robot& robot,
                                 const WheelOrderOptions& options = {});

// The same test scored on segments (segment_residual.h: relative pose error over disjoint windows
// of segment_length_m of ground-truth path, d = 3 W - 9 for W windows) instead of final poses, for
// runs whose ground truth has intermediate poses. Final poses cannot see every miswiring: on full
// circles, swapping two columns of a symmetric robot leaves the yaw rate unchanged, so the
// odometry closes its own circle at the start; the windows see that circle driven the wrong way.
// tracks[i] is the ground truth of runs[i]. With fewer than 4 windows nothing is decided.
WheelOrderReport CheckWheelOrderOnSegments(const std::vector<AlignedRun>& runs,
                                           const std::vector<const GroundTruthTrack*>& tracks,
                                           const Omni3Robot& robot,
                                           const WheelOrderOptions& options = {});

struct RateUnitsReport {
  bool suspicious = false;  // the scale is far outside what the bounds allow
  double scale = 1.0;       // odometry path length / ground-truth path length (pooled)
  std::string likely_unit;  // "deg/s", "rev/s", "rpm" or "" when none is near
  std::string message;      // one line when suspicious
};

RateUnitsReport CheckRateUnits(const std::vector<RunLog>& runs, const Omni3Robot& robot);

}  // namespace fitcal
