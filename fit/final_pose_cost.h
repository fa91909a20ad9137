#pragma once
// Transitional: the omni3 overload of the paper's CF (Palacin Eq. 14) for the callers in
// validation/ and diagnosis/ that still hold omni3 parameter arrays; it forwards to the seam
// (fit/final_pose_errors.h with the omni3 model). Delete with those callers.

#include <array>
#include <vector>

#include "fit/final_pose_errors.h"
#include "models/omni3/omni3_robot_model.h"
#include "odometry/aligned_run.h"
#include "odometry/omni3_model.h"

namespace fitcal {

using Omni3ParameterArray = std::array<double, omni3::kNumParameters>;

inline FinalPoseErrors EvaluateFinalPoseErrors(const Omni3ParameterArray& p,
                                               const std::vector<AlignedRun>& runs,
                                               int num_threads = 0) {
  return EvaluateFinalPoseErrors(DefaultOmni3Model(), std::vector<double>(p.begin(), p.end()), runs,
                                 num_threads);
}

}  // namespace fitcal
