#pragma once
// Fits the ASOC castor parameters (r_c, r_w1, r_w2, d_1, d_2, beta for each castor: 18 values) to
// the final poses of a set of runs with Ceres: the ASOC counterpart of omni3_ceres_fit.h. One
// residual block per run, the final-pose residual of final_pose_residual.h's form
//   r = [(x_f - x_gt) / sigma_xy, (y_f - y_gt) / sigma_xy, wrap(psi_f - psi_gt) / sigma_psi]
// with the pose replayed by CAST (asoc_odometry.h, ReplayCastFinalPose), differentiated with
// autodiff. The pivot layout (R_i, phi_i) is known geometry (Doebbler assume D known) and is held.
//
// Identifiability: final poses of a few runs cannot separate 18 parameters when the runs do not
// excite them (e.g. UMBmark squares alone). The fit is bounded to a box around its start
// (relative_bounds on lengths, bias_bound_rad on beta) and the covariance says what is not
// determined: a rank-deficient covariance is reported, not hidden.

#include <array>
#include <string>
#include <vector>

#include "fit/final_pose_residual.h"
#include "models/asoc/asoc_odometry.h"
#include "models/asoc/asoc_run_log.h"

namespace fitcal::asoc {

// A run prepared for the final-pose cost: encoder samples from the start pose to the final
// ground-truth pose (the run must start where its start pose / first ground truth is).
struct AlignedAsocRun {
  std::string id;
  std::string trajectory;
  int repetition = 0;
  Pose2d start;
  Pose2d final_ground_truth;
  std::vector<EncoderSample> samples;
};

// Clips the encoder samples to the ground truth's time span; the start pose is the run's
// start_pose or the ground truth at the first kept sample, the final pose the ground truth at the
// last kept sample (interpolated). Throws std::invalid_argument when they share no time.
AlignedAsocRun AlignAsocRun(const RunLog& run);

class AsocFinalPoseResidual {
 public:
  static constexpr int kNumResiduals = 3;

  AsocFinalPoseResidual(const AlignedAsocRun& run,
                        const std::array<PivotPosition, kNumCastors>& pivots,
                        const ResidualWeights& weights)
      : run_(run),
        pivots_(pivots),
        inv_position_sigma_(1.0 / weights.position_sigma_m),
        inv_heading_sigma_(1.0 / weights.heading_sigma_rad) {}

  template <typename T>
  bool operator()(const T* p, T* residual) const {
    const Pose2<T> start{T(run_.start.x), T(run_.start.y), T(run_.start.theta)};
    const Pose2<T> final_pose = ReplayCastFinalPose(
        p, pivots_, kAllCastors, false, run_.samples.data(), run_.samples.size(), start);
    const Pose2d& gt = run_.final_ground_truth;
    residual[0] = (final_pose.x - gt.x) * inv_position_sigma_;
    residual[1] = (final_pose.y - gt.y) * inv_position_sigma_;
    residual[2] = WrapAngle(final_pose.theta - gt.theta) * inv_heading_sigma_;
    return true;
  }

  static ceres::CostFunction* Create(const AlignedAsocRun& run,
                                     const std::array<PivotPosition, kNumCastors>& pivots,
                                     const ResidualWeights& weights) {
    return new ceres::AutoDiffCostFunction<AsocFinalPoseResidual, kNumResiduals, kNumParameters>(
        new AsocFinalPoseResidual(run, pivots, weights));
  }

 private:
  const AlignedAsocRun& run_;
  std::array<PivotPosition, kNumCastors> pivots_;
  double inv_position_sigma_;
  double inv_heading_sigma_;
};

struct AsocFitOptions {
  ResidualWeights weights;
  double relative_bounds = 0.15;                // lengths within +-15 % of the start
  double bias_bound_rad = 30.0 * M_PI / 180.0;  // beta within +-30 deg of the start
  int max_num_iterations = 100;
  int num_threads = 0;
  bool compute_covariance = true;
  bool IsValid(std::string* error) const;
};

struct AsocFitResult {
  bool usable = false;
  std::string termination;
  std::string message;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  Vehicle estimate;
  bool has_covariance = false;
  std::string covariance_message;
  std::array<double, kNumParameters> sigma{};  // flat order, scaled by the residual variance
};

// Mean final-pose CF (Palacin Eq. 14 form: mean of |[dx, dy, dpsi]|, m and rad) of CAST-0 replays.
double AsocFinalPoseCf(const Vehicle& vehicle, const std::vector<AlignedAsocRun>& runs);

// Throws std::invalid_argument for invalid options or no runs.
AsocFitResult FitAsocCeres(const std::vector<AlignedAsocRun>& training, const Vehicle& start,
                           const AsocFitOptions& options = {});

}  // namespace fitcal::asoc
