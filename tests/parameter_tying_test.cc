// Parameter tying on the model seam (fit/parameter_tying.h) and the clock map of any model
// (fit/segment_cost.h EstimateClockMap):
//   - an omni3 whose three true wheel distances are equal, fitted with them tied (and the angles
//     held, OptiOdom's reduced model) on noisy final poses: one shared value within 4 of its
//     sigmas of the truth, that sigma shared by the three, the held angles at the nominal;
//   - a differential drive whose true radii are equal, fitted on its tracks with r_left and
//     r_right tied: equal radii within 4 sigmas;
//   - a wrong name is refused by the library and by `fitcal fit --tie` (one line, exit 2), and so
//     is a tie with the effect fit;
//   - the clock map of a simulated differential drive whose ground truth is 0.15 s late.

#include "fit/parameter_tying.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "fit/model_fit.h"
#include "fit/segment_cost.h"
#include "fit/track_residual.h"
#include "io/text_file.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "models/omni3/omni3_robot_model.h"
#include "odometry/aligned_run.h"
#include "tests/test_files.h"
#include "models/diff_drive/diff_drive_trajectories.h"
#include "sim/model_simulator.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace {

// The ground truth's noise in every simulation below, and the fits' residual weights: a final
// pose relative to a start that is itself a noisy ground-truth sample has sqrt(2) times the noise.
constexpr double kGtPositionSigmaM = 0.001;
constexpr double kGtHeadingSigmaRad = 0.002;
// A tolerance of 4 sigmas: a correct fit fails it with probability ~6e-5 per parameter.
constexpr double kSigmas = 4.0;

sim::SimulationOptions NoisyOptions() {
  sim::SimulationOptions o;
  o.gt_position_sigma_m = kGtPositionSigmaM;
  o.gt_heading_sigma_rad = kGtHeadingSigmaRad;
  o.wheel_rate_sigma_rad_s = 0.01;
  o.rest_before_s = 1.0;  // longer than the clock offset below: windows start at rest
  o.rest_after_s = 1.0;
  o.seed = 11;
  return o;
}

CeresFitOptions WeighedByTheNoise() {
  CeresFitOptions o;
  o.num_threads = 1;
  o.weights.position_sigma_m = std::sqrt(2.0) * kGtPositionSigmaM;
  o.weights.heading_sigma_rad = std::sqrt(2.0) * kGtHeadingSigmaRad;
  return o;
}

std::vector<RunLog> Logs(const std::vector<sim::ModelSimulatedRun>& runs) {
  std::vector<RunLog> logs;
  for (const auto& r : runs) logs.push_back(r.log);
  return logs;
}

// Open paths (the final poses see the distances' common scale): straight, sideways, diagonal,
// arcs with spin, a spin on the spot; each 1-2 m or 1-3 rad.
std::vector<sim::TrajectorySpec> OmniTrajectories(int repetitions) {
  std::vector<sim::TrajectorySpec> specs;
  for (int rep = 1; rep <= repetitions; ++rep) {
    specs.push_back({"forward", rep, {{{0.25, 0.0, 0.0}, 6.0}}});
    specs.push_back({"sideways", rep, {{{0.0, 0.25, 0.0}, 5.0}}});
    specs.push_back({"diagonal", rep, {{{0.2, -0.2, 0.0}, 5.0}}});
    specs.push_back({"arc", rep, {{{0.2, 0.05, 0.5}, 5.0}}});
    specs.push_back({"spin", rep, {{{0.0, 0.0, 0.8}, 4.0}}});
  }
  return specs;
}

TEST(ParameterTying, EqualWheelDistancesRecoveredAsOneValueWithItsSigma) {
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kOmni3ExampleYaml), "robot.yaml");
  const Robot& robot = model->robot();
  const int r_a = RequireParameterIndex(robot, "R_a"), r_b = RequireParameterIndex(robot, "R_b"),
            r_c = RequireParameterIndex(robot, "R_c");
  std::vector<double> truth = robot.nominal;
  for (int k : {r_a, r_b, r_c}) truth[k] = 0.201;
  truth[RequireParameterIndex(robot, "r_a")] = 0.150;
  truth[RequireParameterIndex(robot, "r_b")] = 0.146;
  truth[RequireParameterIndex(robot, "r_c")] = 0.149;
  const std::vector<AlignedRun> runs =
      AlignRuns(Logs(sim::SimulateRuns(*model, truth, OmniTrajectories(3), NoisyOptions())));

  ParameterTying tying;
  tying.groups = {{"R_a", "R_b", "R_c"}};
  tying.held = {"delta_a", "delta_b", "delta_c"};
  ModelFitOptions options;
  options.ceres = WeighedByTheNoise();
  options.tying = &tying;
  const ModelFitResult fit = FitModel(runs, *model, options);
  ASSERT_TRUE(fit.usable) << fit.message;
  ASSERT_TRUE(fit.has_covariance) << fit.covariance_message;
  EXPECT_TRUE(fit.held_directions.empty());
  // One value, one sigma, correlation 1 among the three.
  EXPECT_EQ(fit.parameters[r_a], fit.parameters[r_b]);
  EXPECT_EQ(fit.parameters[r_b], fit.parameters[r_c]);
  EXPECT_EQ(fit.sigma[r_a], fit.sigma[r_b]);
  EXPECT_EQ(fit.sigma[r_b], fit.sigma[r_c]);
  EXPECT_NEAR(fit.correlation(r_a, r_c), 1.0, 1e-12);
  // 1 mm ground-truth noise over 1-2 m paths: the scale is known to ~1e-3, R to well below 1 mm.
  EXPECT_GT(fit.sigma[r_a], 0.0);
  EXPECT_LT(fit.sigma[r_a], 1e-3);
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (robot.parameters[k].unit == ParameterUnit::kAngle) {
      EXPECT_TRUE(fit.held[k]) << k;
      EXPECT_EQ(fit.parameters[k], robot.nominal[k]) << k;
      EXPECT_EQ(fit.sigma[k], 0.0) << k;
      continue;
    }
    EXPECT_FALSE(fit.held[k]) << k;
    EXPECT_FALSE(fit.at_bound[k]) << k;
    EXPECT_NEAR(fit.parameters[k], truth[k], kSigmas * fit.sigma[k]) << robot.parameters[k].name;
  }
}

TEST(ParameterTying, DiffDriveRadiiTiedOnTracksComeOutEqual) {
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  const Robot& robot = model->robot();
  std::vector<double> truth = robot.nominal;
  for (double& v : truth) v *= 1.02;  // equal radii, 2 % larger, and the track with them
  const std::vector<RunLog> logs = Logs(
      sim::SimulateRuns(*model, truth, sim::DiffDriveCalibrationTrajectories(2), NoisyOptions()));
  const std::vector<AlignedRun> runs = AlignRuns(logs);
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : logs) tracks.push_back(&log.ground_truth);
  const TrackFitData data = MakeTrackFitData(runs, tracks, ClockGrouping::kNone);

  ParameterTying tying;
  tying.groups = {{"r_left", "r_right"}};
  ModelFitOptions options;
  options.ceres = WeighedByTheNoise();
  options.residuals = ResidualKind::kTrack;
  options.track = &data;
  options.tying = &tying;
  const ModelFitResult fit = FitModel(runs, *model, options);
  ASSERT_TRUE(fit.usable) << fit.message;
  ASSERT_TRUE(fit.has_covariance) << fit.covariance_message;
  const int left = RequireParameterIndex(robot, "r_left");
  const int right = RequireParameterIndex(robot, "r_right");
  EXPECT_EQ(fit.parameters[left], fit.parameters[right]);
  EXPECT_EQ(fit.sigma[left], fit.sigma[right]);
  for (int k = 0; k < robot.NumParameters(); ++k) {
    EXPECT_GT(fit.sigma[k], 0.0) << k;
    EXPECT_NEAR(fit.parameters[k], truth[k], kSigmas * fit.sigma[k]) << robot.parameters[k].name;
  }

  // On final poses (closed loops: the common scale is held at the nominal) the tie holds too.
  options.residuals = ResidualKind::kFinalPose;
  options.track = nullptr;
  const ModelFitResult final_poses = FitModel(runs, *model, options);
  ASSERT_TRUE(final_poses.usable) << final_poses.message;
  EXPECT_EQ(final_poses.parameters[left], final_poses.parameters[right]);
}

TEST(ParameterTying, WrongNamesAreRefused) {
  const Robot& robot = DefaultOmni3Model().robot();
  ParameterTying unknown;
  unknown.groups = {{"R_a", "R_q"}};
  const std::string error = CheckTying(robot, unknown);
  EXPECT_NE(error.find("'R_q'"), std::string::npos) << error;
  EXPECT_NE(error.find("R_a, R_b"), std::string::npos) << error;  // lists the names it has
  EXPECT_THROW(TiedModel(DefaultOmni3Model(), unknown), std::invalid_argument);
  ModelFitOptions options;
  options.tying = &unknown;
  EXPECT_THROW(FitModel({AlignedRun{}}, DefaultOmni3Model(), options), std::invalid_argument);

  ParameterTying twice;
  twice.groups = {{"R_a", "R_b"}};
  twice.held = {"R_b"};
  EXPECT_NE(CheckTying(robot, twice).find("twice"), std::string::npos);
  ParameterTying mixed;
  mixed.groups = {{"R_a", "delta_a"}};
  EXPECT_NE(CheckTying(robot, mixed).find("mixes"), std::string::npos);
  ParameterTying alone;
  alone.groups = {{"R_a"}};
  EXPECT_FALSE(CheckTying(robot, alone).empty());
  EXPECT_EQ(io::SplitCsvFields(" R_a, R_b ,R_c"), (std::vector<std::string>{"R_a", "R_b", "R_c"}));
}

TEST(ParameterTying, FitCommandTiesAndRefusesUnknownNames) {
  testing::TempDir dir;
  const std::string data = dir.Path("diff");
  ASSERT_EQ(
      testing::RunFitcal(dir, "simulate --model diff_drive --out " + data + " --seed 3").exit_code,
      0);
  const std::string cal = dir.Path("cal.yaml");
  const auto tied =
      testing::RunFitcal(dir, "fit --logs " + data + " --tie r_left,r_right --out " + cal);
  ASSERT_EQ(tied.exit_code, 0) << tied.err;
  EXPECT_NE(tied.out.find("tied (one value): r_left=r_right"), std::string::npos) << tied.out;
  // The calibration says why its two radii are equal (stop 72's D-F4), and reads back.
  EXPECT_NE(testing::ReadFileBytes(cal).find("\n  tied: [r_left=r_right]\n"), std::string::npos);
  EXPECT_EQ(testing::RunFitcal(dir, "report --logs " + data + " --calibration " + cal +
                                        " --out " + dir.Path("r"))
                .exit_code,
            0);
  const auto wrong =
      testing::RunFitcal(dir, "fit --logs " + data + " --tie r_left,r_nope --no-output");
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_EQ(std::count(wrong.err.begin(), wrong.err.end(), '\n'), 1) << wrong.err;
  EXPECT_NE(wrong.err.find("'r_nope'"), std::string::npos) << wrong.err;
  EXPECT_EQ(wrong.out, "");
  // The effect fit moves every parameter: a tie cannot apply to it.
  const auto effects = testing::RunFitcal(
      dir, "fit --logs " + data + " --tie r_left,r_right --effects pivot_yaw_gain --no-output");
  EXPECT_EQ(effects.exit_code, 2) << effects.err;
  EXPECT_EQ(std::count(effects.err.begin(), effects.err.end(), '\n'), 1) << effects.err;
}

// Ground truth stamped 0.15 s late on a simulated differential drive: the speed-profile match of
// the model's body velocities finds the offset within one grid step (0.01 s) and no rate error
// beyond one step (0.25 %). Noise-free, so that the grid is the only tolerance: the offset is seen
// through the 0.4 s ramps only, and 1 mm of ground-truth noise at 10 Hz (speed noise ~0.03 m/s
// per 50 ms interval against a 0.005 m/s mismatch per 10 ms of offset during a ramp) moves it
// by ~0.01 s, one step.
TEST(ClockMap, FindsAGroundTruthOffsetOfADiffDrive) {
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml");
  const std::vector<double>& p = model->robot().nominal;
  // Half the wheel separation: a turn moves the wheels as fast as that lever arm.
  EXPECT_NEAR(ClockMapLeverArm(*model, p.data()), 0.100, 1e-12);
  // R for a symmetric omni3 (all three wheels at 0.195 m).
  const RobotModelPtr omni3 = ReadRobotModel(YAML::Load(kOmni3ExampleYaml), "robot.yaml");
  EXPECT_NEAR(ClockMapLeverArm(*omni3, omni3->robot().nominal.data()), 0.195, 1e-12);
  constexpr double kLateS = 0.15;
  sim::SimulationOptions o = NoisyOptions();
  o.gt_position_sigma_m = 0.0;
  o.gt_heading_sigma_rad = 0.0;
  o.wheel_rate_sigma_rad_s = 0.0;
  for (const auto& run :
       sim::SimulateRuns(*model, p, sim::DiffDriveCalibrationTrajectories(1), o)) {
    RunLog log = run.log;
    for (double& t : log.ground_truth.t_s) t += kLateS;
    const ClockMap map = EstimateClockMap(*model, p.data(), AlignRun(run.log), log.ground_truth);
    EXPECT_NEAR(map.offset_s, kLateS, kClockMapOffsetStepS + 1e-9) << log.id;
    EXPECT_NEAR(map.rate, 0.0, kClockMapRateStep + 1e-12) << log.id;
  }
}

}  // namespace
}  // namespace fitcal
