#pragma once
// The paper's cost CF (Palacin Eq. 14) over a set of runs: the mean over runs of
// sqrt(dx^2 + dy^2 + dtheta^2) at the final pose, angle in radians. This is what fitcal reports,
// whatever objective a solver minimises (see seeds/README.md: the paper's Table 6 only agrees
// with the angle term in radians).

#include <array>
#include <vector>

#include "fit/final_pose_errors.h"
#include "odometry/aligned_run.h"
#include "odometry/omni3_model.h"

namespace fitcal {

using Omni3ParameterArray = std::array<double, omni3::kNumParameters>;

// Evaluates every run in parallel (num_threads 0 = all cores).
FinalPoseErrors EvaluateFinalPoseErrors(const Omni3ParameterArray& p,
                                        const std::vector<AlignedRun>& runs, int num_threads = 0);

}  // namespace fitcal
