// Leave-one-repetition-out cross-validation (validation/cross_validation.h), for any model on the
// seam (here the simulated differential drive).
#include "validation/cross_validation.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <stdexcept>

#include "fit/model_fit.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "tests/model_support.h"
#include "sim/model_scenarios.h"

namespace fitcal {
namespace {

std::vector<AlignedRun> SimulatedDiffDrive(const RobotModelInterface& model, int repetitions,
                                           std::vector<double>* truth) {
  sim::ScenarioNoise noise;
  noise.repetitions = repetitions;
  noise.seed = 5;
  *truth = sim::DefaultTrueParameters(model.robot());
  const sim::ModelScenario scenario = sim::MakeModelScenario(model, *truth, noise);
  std::vector<RunLog> logs;
  for (const sim::ModelSimulatedRun& r :
       sim::SimulateRuns(model, *truth, scenario.trajectories, scenario.options)) {
    logs.push_back(r.log);
  }
  return AlignRuns(logs);
}

// Three repetitions give three folds; each holds out exactly one repetition's runs and trains on
// the others; every fold's fit lands on the true robot within the noise: its error is measured
// against the sigma of a fit on two repetitions (the covariance of a fit on all three, scaled by
// sqrt(3/2)), and 4 of those sigmas is allowed (a swapped wheel or a wrong sign moves a radius by
// percent, hundreds of sigmas).
TEST(CrossValidation, EveryModelRefitsEachFoldOnTheOtherRepetitions) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  std::vector<double> truth;
  const std::vector<AlignedRun> runs = SimulatedDiffDrive(*model, 3, &truth);
  const ModelFitResult all = FitModel(runs, *model);
  ASSERT_TRUE(all.usable && all.has_covariance) << all.message;
  const CrossValidationResult cv = LeaveOneRepetitionOut(runs, *model);
  ASSERT_EQ(cv.folds.size(), 3u);
  EXPECT_EQ(cv.usable_folds, 3);
  ASSERT_EQ(cv.parameter_spread.size(), truth.size());
  const int per_repetition = static_cast<int>(runs.size()) / 3;
  for (const CrossValidationFold& fold : cv.folds) {
    SCOPED_TRACE("held out repetition " + std::to_string(fold.held_out_repetition));
    EXPECT_EQ(fold.validation_runs, per_repetition);
    EXPECT_EQ(fold.training_runs, 2 * per_repetition);
    // UMBmark-sized errors (E_d 1.005): the fit removes most of the nominal's error.
    EXPECT_LT(fold.cf_validation_after, 0.5 * fold.cf_validation_before);
    for (std::size_t k = 0; k < truth.size(); ++k) {
      if (model->robot().IsHeld(static_cast<int>(k))) continue;
      EXPECT_NEAR(fold.parameters[k], truth[k], 4.0 * std::sqrt(1.5) * all.sigma[k]) << k;
    }
  }
  EXPECT_EQ(cv.cf_validation_after.count, 3);
  EXPECT_LT(cv.cf_validation_after.mean, cv.cf_validation_before.mean);
}

TEST(CrossValidation, RefusesASingleRepetition) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  std::vector<double> truth;
  const std::vector<AlignedRun> runs = SimulatedDiffDrive(*model, 1, &truth);
  EXPECT_THROW(LeaveOneRepetitionOut(runs, *model), std::invalid_argument);
}

}  // namespace
}  // namespace fitcal
