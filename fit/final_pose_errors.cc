#include "fit/final_pose_errors.h"

#include <cmath>

#include "models/pose_errors.h"
#include "odometry/parallel_for.h"

namespace fitcal {

FinalPoseErrors SummariseFinalPoseResiduals(const std::vector<std::array<double, 3>>& residuals) {
  FinalPoseErrors out;
  const std::size_t n = residuals.size();
  out.per_run_cf.assign(n, 0.0);
  if (n == 0) return out;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& r = residuals[i];
    out.per_run_cf[i] = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    out.cf += out.per_run_cf[i];
    out.mean_position_error_m += std::hypot(r[0], r[1]);
    out.mean_abs_heading_error_rad += std::abs(r[2]);
  }
  out.cf /= static_cast<double>(n);
  out.mean_position_error_m /= static_cast<double>(n);
  out.mean_abs_heading_error_rad /= static_cast<double>(n);
  return out;
}

FinalPoseErrors EvaluateFinalPoseErrors(const RobotModelInterface& model,
                                        const std::vector<double>& p,
                                        const std::vector<AlignedRun>& runs, int num_threads) {
  std::vector<std::array<double, 3>> residuals(runs.size());
  ParallelFor(runs.size(), num_threads, [&](std::size_t i) {
    const Pose2d final_pose = model.ReplayFinalPose(p.data(), runs[i].samples, runs[i].start);
    FinalPoseError(final_pose, runs[i].final_ground_truth, ResidualWeights{}, residuals[i].data());
  });
  return SummariseFinalPoseResiduals(residuals);
}

}  // namespace fitcal
