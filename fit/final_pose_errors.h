#pragma once
// The paper's cost CF (Palacin Eq. 14) over a set of runs, for any robot model: the mean over
// runs of sqrt(dx^2 + dy^2 + dtheta^2) at the final pose, angle in radians. This is what fitcal
// reports, whatever objective a solver minimises (seeds/README.md: the paper's Table 6 only
// agrees with the angle term in radians).

#include <array>
#include <vector>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

struct FinalPoseErrors {
  double cf = 0.0;  // mean per-run CF (Eq. 14)
  double mean_position_error_m = 0.0;
  double mean_abs_heading_error_rad = 0.0;
  std::vector<double> per_run_cf;
};

// Per-run final-pose residuals (models/pose_errors.h, weights 1) reduced to Eq. 14 and the mean
// position and heading errors.
FinalPoseErrors SummariseFinalPoseResiduals(const std::vector<std::array<double, 3>>& residuals);

// Replays every run with the model at p, in parallel (num_threads 0 = all cores).
FinalPoseErrors EvaluateFinalPoseErrors(const RobotModelInterface& model,
                                        const std::vector<double>& p,
                                        const std::vector<AlignedRun>& runs, int num_threads = 0);

}  // namespace fitcal
