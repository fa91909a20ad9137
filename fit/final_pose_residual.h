#pragma once
// The final-pose residual of one run, Palacin Eq. 14: the replayed odometry's final pose minus
// the ground truth's, heading difference wrapped to [-pi, pi). Written once, templated: Ceres
// differentiates it with autodiff; the CF evaluation and the NLopt back end call it on double.
//
//   r = [ (x_f - x_gt_f) / sigma_xy,  (y_f - y_gt_f) / sigma_xy,  wrap(theta_f - theta_gt_f) /
//   sigma_theta ]
//
// With the default sigmas of 1 (m and rad) |r| is the paper's per-run CF.

#include <ceres/autodiff_cost_function.h>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/omni3_replay.h"

namespace fitcal {

class Omni3FinalPoseResidual {
 public:
  static constexpr int kNumResiduals = 3;

  Omni3FinalPoseResidual(const AlignedRun& run, const ResidualWeights& weights)
      : run_(run),
        inv_position_sigma_(1.0 / weights.position_sigma_m),
        inv_heading_sigma_(1.0 / weights.heading_sigma_rad) {}

  template <typename T>
  bool operator()(const T* p, T* residual) const {
    const Pose2<T> start{T(run_.start.x), T(run_.start.y), T(run_.start.theta)};
    ResidualOfFinalPose(omni3::ReplayFinalPose(p, run_.samples, start), residual);
    return true;
  }

  // The residual of a final pose replayed by other means (e.g. with a transformed matrix).
  template <typename T>
  void ResidualOfFinalPose(const Pose2<T>& final_pose, T* residual) const {
    const Pose2d& gt = run_.final_ground_truth;
    residual[0] = (final_pose.x - gt.x) * inv_position_sigma_;
    residual[1] = (final_pose.y - gt.y) * inv_position_sigma_;
    residual[2] = WrapAngle(final_pose.theta - gt.theta) * inv_heading_sigma_;
  }

  static ceres::CostFunction* Create(const AlignedRun& run, const ResidualWeights& weights) {
    return new ceres::AutoDiffCostFunction<Omni3FinalPoseResidual, kNumResiduals,
                                           omni3::kNumParameters>(
        new Omni3FinalPoseResidual(run, weights));
  }

 private:
  const AlignedRun& run_;
  double inv_position_sigma_;
  double inv_heading_sigma_;
};

}  // namespace fitcal
