#pragma once
// Data that let a fit "converge" without saying anything about some parameters, found and said
// out loud (STYLE.md habit 8), for every model on the seam:
//   - a wheel that never turns in any run (disconnected encoder, stuck wheel): its radius has no
//     influence on any residual, the fit leaves it at the nominal;
//   - runs with identical encoder logs (a file copied for another run): they add no information,
//     and when all runs are one, 3 residuals cannot determine the free parameters;
//   - after the fit, runs whose final-pose error is far beyond the others (gross wheel slip, a
//     ground-truth file of another run): with a least-squares loss they pull every parameter.
//
// Outlier test: per-run squared residual norms e_i = |r_i|^2 of the fit. If the runs share one
// Gaussian noise, e_i / s^2 ~ chi^2_k with k <= 3 the residual's effective dimension (k = 1 when
// one component dominates, e.g. position error in metres against heading in radians). The scale
// is estimated robustly, s^2 = median(e) / median(chi^2_k), and run i is an outlier when
// e_i / s^2 > the chi^2_k quantile at 1 - alpha / N (Bonferroni over N runs). k = 1 gives the
// largest threshold relative to the median (|r| about 6x the median |r| for alpha = 1e-3 and
// N = 40), so it is used: the test does not flag a run for the noise being anisotropic.

#include <string>
#include <vector>

#include "odometry/aligned_run.h"
#include "odometry/robot.h"
#include "odometry/run_log.h"

namespace fitcal {

// One sentence per problem found in the runs before fitting (empty: none); the runs' channels are
// the robot's (robot.channels order).
std::vector<std::string> FindDegenerateData(const std::vector<AlignedRun>& runs,
                                            const Robot& robot);

// Runs that stand still teach nothing: every parameter scales motion, and without motion any value
// explains the runs (the fit stays at the nominal and its covariance is the noise's alone, sigmas
// of micrometres that claim a precision the data never had). A run moves when the 90th percentile
// of its ground truth's distance from its median position exceeds kStillPositionM, or that of its
// heading's difference from its median heading exceeds kStillHeadingRad (far above motion-capture
// noise, far below any calibration drive). One line naming why when no run moves ("" otherwise):
// the caller refuses to fit (exit 1). A run whose ground truth holds only its start and end poses
// (a closed loop ends where it began) moves when one of its wheels turned more than
// kStillWheelTurnRad (one turn: far above an encoder's jitter at rest, far below a calibration
// drive); `robot` names its wheel-rate channels.
inline constexpr double kStillPositionM = 0.05;
inline constexpr double kStillHeadingRad = 0.05;
inline constexpr double kStillWheelTurnRad = 2.0 * 3.14159265358979323846;
std::string StillRunsRefusal(const std::vector<const RunLog*>& runs, const Robot& robot);

struct OutlierRun {
  std::string id;
  double error_ratio = 0.0;  // |r_i| / median |r|
};

// Runs whose final-pose residual norm (per_run_norm, same order as run_ids) is an outlier as
// described above; alpha is the family-wise false-alarm probability.
std::vector<OutlierRun> FindOutlierRuns(const std::vector<std::string>& run_ids,
                                        const std::vector<double>& per_run_norm,
                                        double alpha = 1e-3);

// The p-quantile of chi^2 with 1 degree of freedom.
double ChiSquare1Quantile(double p);

}  // namespace fitcal
