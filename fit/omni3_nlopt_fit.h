#pragma once
// Fits the nine omni3 parameters with NLopt (fit/nlopt_search.h: the methods, the normalised box
// of Palacin Eq. 16, the objective, reproducibility) over the SAME per-run residual as the Ceres
// fit (final_pose_residual.h): for the value, its formula on the final pose of the precomputed
// Eq. 4 kernel (odometry/omni3_final_pose_kernel.h, ~3.5x faster than the replay); for the
// gradient, its Ceres autodiff. Other models search through the seam (fit/model_nlopt_fit.h).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fit/final_pose_cost.h"
#include "fit/final_pose_residual.h"
#include "fit/nlopt_search.h"
#include "fit/omni3_ceres_fit.h"
#include "odometry/aligned_run.h"
#include "odometry/robot_description.h"

namespace fitcal {

struct NloptFitResult {
  bool usable = false;           // finite parameters and NLopt stopped on a success code
  std::string termination;       // NLopt's result, e.g. "NLOPT_MAXEVAL_REACHED"
  std::string message;           // the method, polish and stop reason in words
  int evaluations = 0;           // objective evaluations (each one replays every training run)
  int gradient_evaluations = 0;  // of them, evaluations with the gradient
  double solve_time_s = 0.0;
  double initial_objective = 0.0;
  double final_objective = 0.0;
  double initial_cf = 0.0;  // Eq. 14 on the training runs at the nominal parameters
  double final_cf = 0.0;
  Omni3ParameterArray parameters{};
  std::array<bool, omni3::kNumParameters> at_bound{};
  std::vector<ConvergencePoint> trace;  // one point per improvement of the best CF
};

// Throws std::invalid_argument for invalid options or no runs.
NloptFitResult FitOmni3Nlopt(const std::vector<AlignedRun>& training, const Omni3Robot& robot,
                             const NloptFitOptions& options = {});

}  // namespace fitcal
