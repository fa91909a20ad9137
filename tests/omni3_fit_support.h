#pragma once
// The fit `fitcal fit` runs for every model (fit/model_fit.h, fit/model_nlopt_fit.h), on an omni3
// robot of the omni3 loader or the simulator: the paper's fit (Palacin Sec. 2.6) as the tests of
// its golden numbers call it.

#include <vector>

#include "fit/final_pose_errors.h"
#include "fit/model_fit.h"
#include "fit/model_nlopt_fit.h"
#include "models/omni3/omni3_robot_model.h"
#include "tests/omni3_robot.h"

namespace fitcal::testing {

inline ModelFitResult FitOmni3(const std::vector<AlignedRun>& runs, const Omni3Robot& robot,
                               const CeresFitOptions& ceres = {}) {
  ModelFitOptions options;
  options.ceres = ceres;
  return FitModel(runs, *Omni3ModelOf(robot), options);
}

inline NloptSearchResult FitOmni3Nlopt(const std::vector<AlignedRun>& runs,
                                       const Omni3Robot& robot, const NloptFitOptions& options) {
  return FitModelNlopt(runs, *Omni3ModelOf(robot), options);
}

// Eq. 14 errors of omni3 parameters (Eq. 15 order) through the model's replay.
inline FinalPoseErrors Omni3Errors(const std::vector<double>& p,
                                   const std::vector<AlignedRun>& runs) {
  return EvaluateFinalPoseErrors(DefaultOmni3Model(), p, runs);
}

}  // namespace fitcal::testing
