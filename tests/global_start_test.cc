// FitModel's global start (fit/model_fit.h ModelFitOptions::global_start) when the fit from the
// guess ends in a local minimum off every bound: a differential drive whose pose source is a
// sensor mounted at (1.5 m, -0.2 m, 5 deg), guessed 0.3 m, 0.2 m and 5 deg off, with its wheel
// separation 20 % off (0.20 for 0.24) and its radii 5-10 % off, simulated as `fitcal simulate`
// does (sim/model_scenarios.h: squares and circles, encoder and ground-truth noise), fitted
// on the track residuals as `fit` does by default. Measured: from the guess, the fit stops at a
// separation of 0.18 with the mount 0.8 m off and 59 deg of final heading error, on no bound; its
// own sigmas are 2.7-3.9x the box's. The global start must find the truth.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>
#include <vector>

#include "fit/model_fit.h"
#include "fit/track_residual.h"
#include "models/model_registry.h"
#include "models/mounted_model.h"
#include "models/omni/omni_model.h"
#include "odometry/aligned_run.h"
#include "sim/model_scenarios.h"

namespace fitcal {
namespace {

constexpr const char* kWheels =
    "model: diff_drive\nname: d\nbounds: {radius_m: [0.030, 0.060], "
    "wheel_separation_m: [0.150, 0.300]}\n";

RobotModelPtr Guess() {
  return ReadRobotModel(YAML::Load(std::string(kWheels) +
                                   "wheels:\n  - {name: right, radius_m: 0.042}\n"
                                   "  - {name: left, radius_m: 0.042}\n"
                                   "wheel_separation_m: 0.200\n"
                                   "ground_truth_frame: {x_m: 1.2, y_m: 0.0, yaw_deg: 0.0}\n"),
                        "guess.yaml");
}

RobotModelPtr TrueRobot() {
  return ReadRobotModel(YAML::Load(std::string(kWheels) +
                                   "wheels:\n  - {name: right, radius_m: 0.046}\n"
                                   "  - {name: left, radius_m: 0.040}\n"
                                   "wheel_separation_m: 0.240\n"
                                   "ground_truth_frame: {x_m: 1.5, y_m: -0.2, yaw_deg: 5.0}\n"),
                        "truth.yaml");
}

class FarFromTheGuess : public ::testing::Test {
 protected:
  void SetUp() override {
    sim::ScenarioNoise noise;
    noise.repetitions = 3;
    noise.seed = 5;
    const sim::ModelScenario scenario = sim::MakeModelScenario(*model_, truth_, noise);
    for (auto& run : sim::SimulateRuns(*model_, truth_, scenario.trajectories, scenario.options)) {
      logs_.push_back(std::move(run.log));
    }
    runs_ = AlignRuns(logs_);
    std::vector<const GroundTruthTrack*> tracks;
    for (const RunLog& log : logs_) tracks.push_back(&log.ground_truth);
    track_ = MakeTrackFitData(runs_, tracks, ClockGrouping::kNone);
    options_.residuals = ResidualKind::kTrack;
    options_.track = &track_;
    options_.ceres.num_threads = 2;
  }

  const RobotModelPtr model_ = Guess();
  const RobotModelPtr true_robot_ = TrueRobot();
  const std::vector<double> truth_ = true_robot_->robot().nominal;
  std::vector<RunLog> logs_;
  std::vector<AlignedRun> runs_;
  TrackFitData track_;
  ModelFitOptions options_;
};

TEST_F(FarFromTheGuess, ALocalMinimumOffTheBoundsIsLeftForTheTruth) {
  const Robot& robot = model_->robot();
  const ModelFitResult fit = FitModel(runs_, *model_, options_);
  std::printf("global start: %s\n", fit.global_start.c_str());
  ASSERT_TRUE(fit.usable);
  ASSERT_TRUE(fit.has_covariance);
  EXPECT_NE(fit.global_start.find("far above the noise"), std::string::npos) << fit.global_start;
  EXPECT_NE(fit.global_start.find("kept"), std::string::npos) << fit.global_start;
  // Every parameter within 3 of its sigma (the fit's covariance scaled by the residuals it left:
  // derived from the simulated noise) of the truth.
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const double miss = (fit.parameters[k] - truth_[k]) / fit.sigma[k];
    std::printf("%-18s truth %.6g fitted %.6g: %+.2f sigma\n", robot.parameters[k].name.c_str(),
                truth_[k], fit.parameters[k], miss);
    EXPECT_LT(std::abs(miss), 3.0) << robot.parameters[k].name;
  }

  // Without the global start the same fit stays in the local minimum: the separation more than
  // 0.02 m (60 of the sigmas above) from the truth, and the result says nothing was tried.
  ModelFitOptions local_only = options_;
  local_only.global_start = false;
  const ModelFitResult local = FitModel(runs_, *model_, local_only);
  EXPECT_TRUE(local.global_start.empty());
  EXPECT_GT(std::abs(local.parameters[2] - truth_[2]), 0.02) << local.parameters[2];
  EXPECT_GT(local.final_cost, 100.0 * fit.final_cost);
}

// On final poses alone (`fit --residuals final-pose`) the fit from the guess stops where its
// covariance is rank deficient (measured through the command line: separation 0.166, mount 0.9 m
// off, cost 68.0); that too sends it across the box, where the cost falls by orders of magnitude
// (measured 0.0507). Closed loops' final poses leave the common scale of wheels and track
// undetermined (held at the nominal, fit/determined_directions.h), so only the cost is compared.
TEST_F(FarFromTheGuess, OnFinalPosesARankDeficientLocalFitIsLeftToo) {
  ModelFitOptions final_poses;
  final_poses.ceres.num_threads = 2;
  const ModelFitResult fit = FitModel(runs_, *model_, final_poses);
  std::printf("global start: %s\n", fit.global_start.c_str());
  ASSERT_TRUE(fit.usable);
  EXPECT_NE(fit.global_start.find("kept"), std::string::npos) << fit.global_start;
  final_poses.global_start = false;
  const ModelFitResult local = FitModel(runs_, *model_, final_poses);
  std::printf("cost from the guess %g, kept %g\n", local.final_cost, fit.final_cost);
  EXPECT_GT(local.final_cost, 100.0 * fit.final_cost);
}

// Guessed right, the fit explains the runs to their noise: no start across the box is tried (the
// clean case pays for none).
TEST_F(FarFromTheGuess, AFitThatExplainsTheRunsTriesNoOtherStart) {
  const ModelFitResult fit = FitModel(runs_, *true_robot_, options_);
  ASSERT_TRUE(fit.usable);
  EXPECT_TRUE(fit.global_start.empty()) << fit.global_start;
}

// A direction the runs truly leave open: an omni robot's pose source on a mount, guessed right,
// fitted with the mount's x and y free (MountedModel::WithSidewaysMountFreed, the probe
// calibrate/calibrate.cc makes): x and y trade with the wheel distances, so the fit holds that
// direction from any start. The fit of 0.5 m windows is tried first and ends where the guess's
// fit ended: the search stops there, the guess's fit kept as it was. Before, every start across
// the box was tried and held the direction again (a simulated ASOC robot: 88-137 s).
TEST(GlobalStartOnAFlatDirection, EndsWhereTheWindowsFitMeetsTheGuesssMinimum) {
  const RobotModelPtr model = ReadRobotModel(
      YAML::Load(std::string(kOmniExampleYaml) +
                 "ground_truth_frame: {x_m: 0.3, y_m: -0.1, yaw_deg: 5.0}\n"),
      "omni.yaml");
  const auto* mounted = dynamic_cast<const MountedModel*>(model.get());
  ASSERT_NE(mounted, nullptr);
  const RobotModelPtr freed = mounted->WithSidewaysMountFreed();
  ASSERT_NE(freed, nullptr);
  sim::ScenarioNoise noise;
  noise.repetitions = 2;
  noise.seed = 3;
  const std::vector<double> truth = model->robot().nominal;
  const sim::ModelScenario scenario = sim::MakeModelScenario(*model, truth, noise);
  std::vector<RunLog> logs;
  for (auto& run : sim::SimulateRuns(*model, truth, scenario.trajectories, scenario.options)) {
    logs.push_back(std::move(run.log));
  }
  const std::vector<AlignedRun> runs = AlignRuns(logs);
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : logs) tracks.push_back(&log.ground_truth);
  TrackFitData track = MakeTrackFitData(runs, tracks, ClockGrouping::kNone);
  ModelFitOptions options;
  options.residuals = ResidualKind::kTrack;
  options.track = &track;
  options.ceres.num_threads = 2;

  const ModelFitResult fit = FitModel(runs, *freed, options);
  std::printf("global start: %s\n", fit.global_start.c_str());
  ASSERT_TRUE(fit.usable);
  EXPECT_FALSE(fit.held_directions.empty());
  EXPECT_NE(fit.global_start.find("the fit of 0.5 m windows (it ended where the guess's did)"),
            std::string::npos)
      << fit.global_start;
  EXPECT_EQ(fit.global_start.find("across the box"), std::string::npos) << fit.global_start;
  ModelFitOptions local_only = options;
  local_only.global_start = false;
  const ModelFitResult local = FitModel(runs, *freed, local_only);
  EXPECT_EQ(fit.parameters, local.parameters);
}

}  // namespace
}  // namespace fitcal
