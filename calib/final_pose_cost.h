#pragma once
// The paper's cost CF (Palacin Eq. 14) over a set of runs: the mean over runs of
// sqrt(dx^2 + dy^2 + dtheta^2) at the final pose, angle in radians. This is what fitcal reports,
// whatever objective a solver minimises (see seeds/README.md: the paper's Table 6 only agrees
// with the angle term in radians).

#include <array>
#include <vector>

#include "calib/aligned_run.h"
#include "odometry/omni3_model.h"

namespace fitcal {

struct FinalPoseErrors {
  double cf = 0.0;  // mean per-run CF (Eq. 14)
  double mean_position_error_m = 0.0;
  double mean_abs_heading_error_rad = 0.0;
  std::vector<double> per_run_cf;
};

using Omni3ParameterArray = std::array<double, omni3::kNumParameters>;

// Evaluates every run in parallel (num_threads 0 = all cores).
FinalPoseErrors EvaluateFinalPoseErrors(const Omni3ParameterArray& p,
                                        const std::vector<AlignedRun>& runs, int num_threads = 0);

}  // namespace fitcal
