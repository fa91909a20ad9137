// The odometry covariance from held-out residuals (validation/odometry_covariance.h), validated as
// issue 33 asks: simulated robots with known noise, the covariance estimated from the held-out
// runs of one data set (the calibration fitted on its training runs), checked on every run of a
// second data set of the same robot (another seed). The share of errors inside 1 and 2 sigma must
// be near a Gaussian's 68.3 % and 95.4 %: within 60-76 % and 90-98 % (issue 33's targets).
//
// Sample sizes. Each axis's variance is a mean square over n = 72 held-out runs (pose) or
// thousands of windows (twist): for Gaussian errors sigma is known to 1 / sqrt(2 n) = 8 %, which
// moves the 1-sigma share by about 2 phi(1) x 8 % = 4 %; the check's share of 288 run-axis errors
// has a binomial sigma of 2.7 % at 68 % and 1.2 % at 95 %. The twist shares, over thousands of
// windows, are far tighter.
//
// Measured across seeds (pairs 11/12, 21/22, 31/32, 41/42; this test runs the first): twist
// 67.7-69.2 % and 95.3-95.8 % for both robots; pose 67-76 % and 93-95.4 % for the tricycle, but
// 57-74 % and 88-96.5 % for the diff drive, whose final-pose errors are mostly each trajectory's
// systematic error (the squares' pivot turns, the circles' arcs), not a random walk in distance:
// the per-metre pose covariance is the weaker of the two (docs/ros2.md). The seeds are fixed: the
// test is deterministic.

#include "validation/odometry_covariance.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "fit/model_fit.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "models/tricycle/tricycle_model.h"
#include "odometry/aligned_run.h"
#include "tools/sim/diff_drive_trajectories.h"
#include "tools/sim/model_simulator.h"
#include "tools/sim/tricycle_trajectories.h"

namespace fitcal {
namespace {

struct RobotCase {
  const char* name;
  std::string yaml;
  std::vector<double> truth;
  std::vector<sim::TrajectorySpec> (*trajectories)(int repetitions);
};

std::vector<sim::TrajectorySpec> DiffDrive(int repetitions) {
  return sim::DiffDriveCalibrationTrajectories(repetitions);
}

std::vector<sim::TrajectorySpec> Tricycle(int repetitions) {
  sim::TricycleTrajectoryOptions o;
  o.repetitions = repetitions;
  return sim::TricycleTrajectories(o);
}

// Known noise: wheel rates 0.02 rad/s white per 20 ms sample, encoder ticks 4096 per turn, ground
// truth 2 mm and 0.2 deg at 10 Hz (the simulator's scenario defaults).
std::vector<RunLog> Simulate(const RobotModelInterface& model, const RobotCase& c, int reps,
                             std::uint64_t seed) {
  sim::SimulationOptions o;
  o.encoder_period_s = 0.02;
  o.ground_truth_period_s = 0.1;
  o.wheel_rate_sigma_rad_s = 0.02;
  o.angle_sigma_rad = 0.1 * M_PI / 180.0;
  o.gt_position_sigma_m = 0.002;
  o.gt_heading_sigma_rad = 0.2 * M_PI / 180.0;
  o.seed = seed;
  std::vector<RunLog> runs;
  for (const sim::ModelSimulatedRun& r : sim::SimulateRuns(model, c.truth, c.trajectories(reps), o)) {
    runs.push_back(r.log);
  }
  return runs;
}

class Coverage : public ::testing::TestWithParam<RobotCase> {};

TEST_P(Coverage, HeldOutErrorsInsideOneAndTwoSigma) {
  const RobotCase& c = GetParam();
  const RobotModelPtr model = ReadRobotModel(YAML::Load(c.yaml), "robot.yaml");
  const std::vector<RunLog> first = Simulate(*model, c, 16, 11);
  std::vector<RunLog> training, held_out;
  for (const RunLog& r : first) (r.repetition <= 4 ? training : held_out).push_back(r);
  const ModelFitResult fit = FitModel(AlignRuns(training), *model);
  ASSERT_TRUE(fit.usable) << fit.termination << ": " << fit.message;

  const OdometryCovariance covariance = EstimateOdometryCovariance(
      CollectOdometryErrors(*model, fit.parameters, held_out, 1.0), 1.0);
  const OdometryErrors unseen =
      CollectOdometryErrors(*model, fit.parameters, Simulate(*model, c, 16, 12), 1.0);
  const OdometryCoverage coverage = CoverageOf(covariance, unseen);
  std::printf("%s: twist %.1f %% / %.1f %% of %zu, pose %.1f %% / %.1f %% of %zu\n", c.name,
              100 * coverage.twist_within_1_sigma, 100 * coverage.twist_within_2_sigma,
              coverage.twist_samples, 100 * coverage.pose_within_1_sigma,
              100 * coverage.pose_within_2_sigma, coverage.pose_samples);
  EXPECT_GE(coverage.twist_samples, 3000u);  // held out: repetitions 5-16
  EXPECT_GE(coverage.pose_samples, 288u);
  EXPECT_GE(coverage.twist_within_1_sigma, 0.60);
  EXPECT_LE(coverage.twist_within_1_sigma, 0.76);
  EXPECT_GE(coverage.twist_within_2_sigma, 0.90);
  EXPECT_LE(coverage.twist_within_2_sigma, 0.98);
  EXPECT_GE(coverage.pose_within_1_sigma, 0.60);
  EXPECT_LE(coverage.pose_within_1_sigma, 0.76);
  EXPECT_GE(coverage.pose_within_2_sigma, 0.90);
  EXPECT_LE(coverage.pose_within_2_sigma, 0.98);
}

INSTANTIATE_TEST_SUITE_P(
    Robots, Coverage,
    ::testing::Values(
        RobotCase{"diff_drive", kDiffDriveExampleYaml, {0.0426, 0.0414, 0.2065}, DiffDrive},
        RobotCase{"tricycle", kTricycleExampleYaml, {0.0331, 0.152, 1.5 * M_PI / 180}, Tricycle}),
    [](const ::testing::TestParamInfo<RobotCase>& p) { return std::string(p.param.name); });

// The estimate itself: errors of known variance give it back.
TEST(OdometryCovariance, MeanSquaresPerAxisAndPerMetre) {
  OdometryErrors e;
  e.twist = {{0.1, -0.2, 0.3}, {-0.3, 0.2, -0.3}};
  e.pose = {{0.02, 0.0, 0.01}, {0.0, 0.04, 0.0}};
  e.path_m = {4.0, 16.0};
  const OdometryCovariance c = EstimateOdometryCovariance(e, 1.0);
  EXPECT_NEAR(c.twist_variance[0], 0.05, 1e-15);
  EXPECT_NEAR(c.twist_variance[2], 0.09, 1e-15);
  EXPECT_NEAR(c.pose_variance_per_m[0], 0.5 * 0.0004 / 4.0, 1e-15);
  EXPECT_NEAR(c.pose_variance_per_m[1], 0.5 * 0.0016 / 16.0, 1e-15);
  const OdometryCoverage k = CoverageOf(c, e);
  EXPECT_EQ(k.twist_samples, 6u);
  // Axis 0: 0.1 inside sqrt(0.05) = 0.22, 0.3 outside and inside 2 sigma; axis 1: both at
  // their RMS 0.2 (inside, up to rounding either way: not counted here); axis 2 likewise.
  EXPECT_GE(k.twist_within_2_sigma, 4.0 / 6.0);
  EXPECT_LE(k.twist_within_1_sigma, 5.0 / 6.0);
}

}  // namespace
}  // namespace fitcal
