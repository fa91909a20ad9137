#pragma once
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

// The scores and the decision of the test above, for this check and for the channel-order check
// of any model (channel_order_check.h); each report adds the mapping it found.
struct MiswiringScores {
  bool likely_miswired = false;  // another mapping explains the data far better
  double recorded_nominal_ssr = 0.0;
  double best_nominal_ssr = 0.0;
  bool fitted = false;         // SSRs below are after a bounded fit of both hypotheses
  double recorded_ssr = 0.0;   // SSR of the recorded order (fitted when `fitted`)
  double best_ssr = 0.0;       // SSR of the best other mapping (fitted when `fitted`)
  double threshold = 0.0;      // the F quantile the ratio recorded/best had to exceed
  int degrees_of_freedom = 0;  // 0: nothing was decided (too few windows)
  std::string message;         // one line when likely_miswired
};

struct WheelOrderReport : MiswiringScores {
  WheelMapping best;  // the best-scoring mapping (identity when not miswired)
};

// What the decision needs besides the nominal SSRs: how many residuals the SSRs sum and how many
// parameters a fit frees (d above), how many other mappings were scored (Bonferroni), the fit of
// a hypothesis, and the words of the message.
struct MiswiringTest {
  int num_residuals = 0;
  int num_free_parameters = 0;
  std::size_t num_alternatives = 0;
  double false_alarm_probability = 0.0;
  // The SSR after a bounded fit of the best other mapping (true) or of the recorded one (false).
  std::function<double(bool best_other)> fitted_ssr;
  std::function<std::string()> describe_best;  // the best other mapping in words
  std::string evidence;                        // e.g. "final-pose SSR"
  std::string sample;                          // e.g. "36 runs"
  std::string order;                           // what to fix in the robot YAML, e.g. "wheel order"
};

// The options this check and the channel-order check share: alpha in (0, 1), positive weights.
bool IsValidMiswiringOptions(double false_alarm_probability, const ResidualWeights& weights,
                             std::string* error);

// The decision of the header on scores whose recorded_nominal_ssr and best_nominal_ssr are set:
// fills the rest of *scores (both hypotheses fitted when the other beats the recorded one at the
// nominal and d allows it).
void DecideMiswiring(const MiswiringTest& test, MiswiringScores* scores);

// sum_i ssr(i) over n runs: each run's term computed in parallel, the sum taken in run order (the
// same bits on any number of threads).
template <typename Fn>
double SumOverRuns(std::size_t n, int num_threads, Fn&& ssr) {
  std::vector<double> per_run(n, 0.0);
  ParallelFor(n, num_threads, [&](std::size_t i) { per_run[i] = ssr(i); });
  double sum = 0.0;
  for (double v : per_run) sum += v;
  return sum;
}

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

// The p-quantile of Fisher's F(d1, d2) (the threshold above), by bisection on statistics.h.
double FDistributionQuantile(double p, double d1, double d2);

}  // namespace fitcal
