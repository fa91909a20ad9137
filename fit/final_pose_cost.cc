#include "fit/final_pose_cost.h"

#include <cmath>

#include "fit/final_pose_residual.h"
#include "odometry/parallel_for.h"

namespace fitcal {

FinalPoseErrors EvaluateFinalPoseErrors(const Omni3ParameterArray& p,
                                        const std::vector<AlignedRun>& runs, int num_threads) {
  std::vector<std::array<double, 3>> residuals(runs.size());
  ParallelFor(runs.size(), num_threads, [&](std::size_t i) {
    Omni3FinalPoseResidual(runs[i], ResidualWeights{})(p.data(), residuals[i].data());
  });
  return SummariseFinalPoseResiduals(residuals);
}

}  // namespace fitcal
