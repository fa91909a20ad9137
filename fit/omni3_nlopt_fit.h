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

// The search's summary (Eq. 14 at the nominal parameters for initial_cf) with the nine
// parameters.
struct NloptFitResult : NloptSearchSummary {
  Omni3ParameterArray parameters{};
  std::array<bool, omni3::kNumParameters> at_bound{};
};

// Throws std::invalid_argument for invalid options or no runs.
NloptFitResult FitOmni3Nlopt(const std::vector<AlignedRun>& training, const Omni3Robot& robot,
                             const NloptFitOptions& options = {});

}  // namespace fitcal
