#include "validation/cross_validation.h"

#include <functional>
#include <set>
#include <stdexcept>

#include "fit/final_pose_errors.h"

namespace fitcal {
namespace {

struct FoldFit {
  bool usable = false;
  std::string termination;
  std::vector<double> parameters;
};
using FoldFitter = std::function<FoldFit(const std::vector<AlignedRun>& training)>;
using RunsCf =
    std::function<double(const std::vector<double>& p, const std::vector<AlignedRun>& runs)>;

// The folds, whatever fits them: `fit` refits on a fold's training runs, `cf` scores parameters.
CrossValidationResult CrossValidate(const std::vector<AlignedRun>& runs,
                                    const std::vector<double>& nominal, const FoldFitter& fit,
                                    const RunsCf& cf) {
  std::set<int> repetitions;
  for (const AlignedRun& run : runs) repetitions.insert(run.repetition);
  if (repetitions.size() < 2) {
    throw std::invalid_argument("cross-validation needs runs of at least two repetitions (found " +
                                std::to_string(repetitions.size()) + ")");
  }
  CrossValidationResult result;
  std::vector<std::vector<double>> values(nominal.size());
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
    const FoldFit f = fit(training);
    fold.usable = f.usable;
    fold.termination = f.termination;
    fold.parameters = f.parameters;
    fold.cf_training = cf(f.parameters, training);
    fold.cf_validation_before = cf(nominal, validation);
    fold.cf_validation_after = cf(f.parameters, validation);
    if (fold.usable) {
      ++result.usable_folds;
      for (std::size_t k = 0; k < nominal.size(); ++k) values[k].push_back(f.parameters[k]);
      cf_after.push_back(fold.cf_validation_after);
      cf_before.push_back(fold.cf_validation_before);
    }
    result.folds.push_back(std::move(fold));
  }
  for (std::vector<double>& v : values) result.parameter_spread.push_back(Summarize(std::move(v)));
  result.cf_validation_after = Summarize(cf_after);
  result.cf_validation_before = Summarize(cf_before);
  return result;
}

}  // namespace

CrossValidationResult LeaveOneRepetitionOut(const std::vector<AlignedRun>& runs,
                                            const RobotModelInterface& model,
                                            const ModelFitOptions& options) {
  ModelFitOptions fold_options = options;
  fold_options.ceres.compute_covariance = false;  // the spread across folds is the point here
  const int threads = options.ceres.num_threads;
  return CrossValidate(
      runs, model.robot().nominal,
      [&](const std::vector<AlignedRun>& training) {
        const ModelFitResult fit = FitModel(training, model, fold_options);
        return FoldFit{fit.usable, fit.termination, fit.parameters};
      },
      [&](const std::vector<double>& p, const std::vector<AlignedRun>& on) {
        return EvaluateFinalPoseErrors(model, p, on, threads).cf;
      });
}

}  // namespace fitcal
