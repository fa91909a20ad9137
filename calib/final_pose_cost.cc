#include "calib/final_pose_cost.h"

#include <cmath>

#include "calib/final_pose_residual.h"
#include "odometry/parallel_for.h"

namespace fitcal {

FinalPoseErrors EvaluateFinalPoseErrors(const Omni3ParameterArray& p,
                                        const std::vector<AlignedRun>& runs, int num_threads) {
  FinalPoseErrors out;
  const std::size_t n = runs.size();
  out.per_run_cf.assign(n, 0.0);
  std::vector<double> position(n), heading(n);
  ParallelFor(n, num_threads, [&](std::size_t i) {
    double r[3];
    Omni3FinalPoseResidual(runs[i], ResidualWeights{})(p.data(), r);
    position[i] = std::hypot(r[0], r[1]);
    heading[i] = std::abs(r[2]);
    out.per_run_cf[i] = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  });
  if (n == 0) return out;
  for (std::size_t i = 0; i < n; ++i) {
    out.cf += out.per_run_cf[i];
    out.mean_position_error_m += position[i];
    out.mean_abs_heading_error_rad += heading[i];
  }
  out.cf /= static_cast<double>(n);
  out.mean_position_error_m /= static_cast<double>(n);
  out.mean_abs_heading_error_rad /= static_cast<double>(n);
  return out;
}

}  // namespace fitcal
