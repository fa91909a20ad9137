#include "validation/cross_validation.h"

#include <set>
#include <stdexcept>

namespace fitcal {

CrossValidationResult LeaveOneRepetitionOut(const std::vector<AlignedRun>& runs,
                                            const Omni3Robot& robot,
                                            const CeresFitOptions& options) {
  std::set<int> repetitions;
  for (const AlignedRun& run : runs) repetitions.insert(run.repetition);
  if (repetitions.size() < 2) {
    throw std::invalid_argument("cross-validation needs runs of at least two repetitions (found " +
                                std::to_string(repetitions.size()) + ")");
  }
  CeresFitOptions fold_options = options;
  fold_options.compute_covariance = false;  // the spread across folds is the point here
  const Omni3ParameterArray nominal = robot.nominal.ToArray();
  CrossValidationResult result;
  std::array<std::vector<double>, omni3::kNumParameters> values;
  std::vector<double> cf_after, cf_before;
  for (int held_out : repetitions) {
    std::vector<AlignedRun> training, validation;
    for (const AlignedRun& run : runs) {
      (run.repetition == held_out ? validation : training).push_back(run);
    }
    CrossValidationFold fold;
    fold.held_out_repetition = held_out;
    fold.training_runs = static_cast<int>(training.size());
    fold.validation_runs = static_cast<int>(validation.size());
    const Omni3FitResult fit = FitOmni3Ceres(training, robot, fold_options);
    fold.usable = fit.usable;
    fold.termination = fit.termination;
    fold.parameters = fit.parameters;
    fold.cf_training = EvaluateFinalPoseErrors(fit.parameters, training, options.num_threads).cf;
    fold.cf_validation_before =
        EvaluateFinalPoseErrors(nominal, validation, options.num_threads).cf;
    fold.cf_validation_after =
        EvaluateFinalPoseErrors(fit.parameters, validation, options.num_threads).cf;
    if (fold.usable) {
      ++result.usable_folds;
      for (int k = 0; k < omni3::kNumParameters; ++k) values[k].push_back(fit.parameters[k]);
      cf_after.push_back(fold.cf_validation_after);
      cf_before.push_back(fold.cf_validation_before);
    }
    result.folds.push_back(fold);
  }
  for (int k = 0; k < omni3::kNumParameters; ++k) result.parameter_spread[k] = Summarize(values[k]);
  result.cf_validation_after = Summarize(cf_after);
  result.cf_validation_before = Summarize(cf_before);
  return result;
}

}  // namespace fitcal
