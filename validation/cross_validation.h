#pragma once
// Leave-one-repetition-out cross-validation of a fit: for every repetition present in the runs,
// fit on all other repetitions and validate (Palacin Eq. 14 CF) on the held-out one. The spread
// of the fitted parameters across folds shows how much a calibration depends on which
// repetitions it saw; the spread of the validation CF shows how well it generalises.
//
// Any model on the seam refits with the bounded final-pose fit (fit/model_fit.h, undetermined
// directions held as `fitcal fit` holds them) and scores with the model's replay (Eq. 14).

#include <string>
#include <vector>

#include "fit/model_fit.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "validation/trajectory_metrics.h"

namespace fitcal {

struct CrossValidationFold {
  int held_out_repetition = 0;
  int training_runs = 0;
  int validation_runs = 0;
  bool usable = false;                // the fold's fit converged
  std::string termination;            // the fold's Ceres termination type
  std::vector<double> parameters;     // the model's parameter order (SI and rad)
  double cf_training = 0.0;           // fitted parameters on the fold's training runs
  double cf_validation_before = 0.0;  // nominal parameters on the held-out repetition
  double cf_validation_after = 0.0;   // fitted parameters on the held-out repetition
};

struct CrossValidationResult {
  std::vector<CrossValidationFold> folds;
  int usable_folds = 0;
  // Over the usable folds: per parameter (the model's order) and for the validation CF.
  std::vector<SummaryStatistics> parameter_spread;
  SummaryStatistics cf_validation_after;
  SummaryStatistics cf_validation_before;
};

// Needs runs of at least two repetitions and throws std::invalid_argument otherwise.
CrossValidationResult LeaveOneRepetitionOut(const std::vector<AlignedRun>& runs,
                                            const RobotModelInterface& model,
                                            const ModelFitOptions& options = {});

}  // namespace fitcal
