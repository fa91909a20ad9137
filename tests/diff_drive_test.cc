// The differential-drive model on the model seam: kinematics against a hand-derived
// arc, autodiff against central differences, the robot YAML (round trip, malformed input),
// UMBmark (a worked example from the paper's equations, recovery of a simulated robot), the
// generic simulator, recovery of a simulated robot by the Ceres fit within sigmas derived from
// the noise, and the import of real OptiOdom sessions (skipped without ../shared).

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "fit/final_pose_errors.h"
#include "fit/model_fit.h"
#include "fit/segment_cost.h"
#include "io/input_error.h"
#include "io/log_files.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/diff_drive/umbmark.h"
#include "models/model_registry.h"
#include "models/pose_errors.h"
#include "odometry/aligned_run.h"
#include "tests/model_support.h"
#include "tests/test_files.h"
#include "interchange/optiodom/optiodom_import.h"
#include "models/diff_drive/diff_drive_trajectories.h"
#include "sim/model_simulator.h"
#include "diagnosis/channel_order_check.h"
#include "validation/rate_units.h"
#include "validation/generalisation.h"

namespace fitcal {
namespace diff_drive_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

namespace fs = std::filesystem;

RobotModelPtr ModelFromYaml(const std::string& text) {
  return ReadRobotModel(YAML::Load(text), "robot.yaml");
}

// Left wheel first, wheels named by their motor, sides given explicitly.
const char* kLeftFirstYaml = R"(model: diff_drive
name: test_left_first
wheels:
  - {name: m1, side: left, radius_m: 0.041}
  - {name: m2, side: right, radius_m: 0.043}
wheel_separation_m: 0.210
bounds: {radius_m: [0.038, 0.046], wheel_separation_m: [0.180, 0.220]}
encoder: {ticks_per_rev: 2796.8, cumulative: false}
)";

// ---------------------------------------------------------------------------------------------
// Kinematics

// Constant wheel rates drive the axle's midpoint on a circle. Hand derivation: r_R = 0.05 m,
// r_L = 0.04 m, w_R = 4 rad/s, w_L = 2.5 rad/s give wheel speeds v_R = 0.2, v_L = 0.1 m/s; the
// robot turns at omega = (v_R - v_L) / b = 0.1 / 0.3 = 1/3 rad/s on a circle of radius
// rho = (b / 2) (v_R + v_L) / (v_R - v_L) = 0.15 * 3 = 0.45 m centred at (0, rho) (left: the
// right wheel is faster). After T = 3 s: theta = 1 rad, x = rho sin 1, y = rho (1 - cos 1).
TEST(DiffDriveKinematics, ConstantRatesReplayTheHandDerivedArc) {
  const double p[3] = {0.05, 0.04, 0.3};  // right first
  const double rho = 0.45;
  EncoderSamples samples(2);
  for (int k = 0; k < 300; ++k) samples.push_back(0.01, {4.0, 2.5});
  double worst_off_circle = 0.0;
  const Pose2d end = ReplayKinematics<DiffDriveKinematics>(
      p, samples, 0, samples.size(), Pose2d{}, [&](std::size_t, const Pose2d& q) {
        worst_off_circle = std::max(worst_off_circle, std::abs(std::hypot(q.x, q.y - rho) - rho));
      });
  EXPECT_NEAR(end.theta, 1.0, 1e-12);
  EXPECT_NEAR(end.x, rho * std::sin(1.0), 1e-12);
  EXPECT_NEAR(end.y, rho * (1.0 - std::cos(1.0)), 1e-12);
  // Every step is an exact chord of the arc: every pose is on the circle.
  EXPECT_LT(worst_off_circle, 1e-12);

  // The same robot described left wheel first, fed the columns in that order, drives the same
  // arc; fed the right-first columns it would mirror it (a swapped wheel is not silent).
  const double q[3] = {0.04, 0.05, 0.3};
  EncoderSamples left_first(2);
  for (int k = 0; k < 300; ++k) left_first.push_back(0.01, {2.5, 4.0});
  const Pose2d same = ReplayKinematics<DiffDriveKinematicsT<1>>(q, left_first, 0, 300, Pose2d{});
  EXPECT_NEAR(same.x, end.x, 1e-12);
  EXPECT_NEAR(same.y, end.y, 1e-12);
  const Pose2d mirrored = ReplayKinematics<DiffDriveKinematicsT<1>>(q, samples, 0, 300, Pose2d{});
  EXPECT_NEAR(mirrored.theta, -(4.0 * 0.04 - 2.5 * 0.05) * 3.0 / 0.3, 1e-12);
}

TEST(DiffDriveKinematics, InverseKinematicsAndSidewaysMotion) {
  const double p[3] = {0.05, 0.04, 0.3};
  double w[2];
  // w_R = (vx + omega b / 2) / r_R = (0.15 + 0.05) / 0.05 = 4, w_L = (0.15 - 0.05) / 0.04 = 2.5.
  ASSERT_TRUE(DiffDriveKinematics::ChannelsForTwist(p, {0.15, 0.0, 1.0 / 3.0}, w));
  EXPECT_NEAR(w[0], 4.0, 1e-12);
  EXPECT_NEAR(w[1], 2.5, 1e-12);
  ASSERT_TRUE(DiffDriveKinematicsT<1>::ChannelsForTwist(p, {0.15, 0.0, 1.0 / 3.0}, w));
  EXPECT_NEAR(w[1], (0.15 + 0.05) / 0.04, 1e-12);  // the right wheel is channel 1: r_R = p[1]
  EXPECT_NEAR(w[0], (0.15 - 0.05) / 0.05, 1e-12);
  EXPECT_FALSE(DiffDriveKinematics::ChannelsForTwist(p, {0.1, 0.01, 0.0}, w));
}

// ---------------------------------------------------------------------------------------------
// Simulated runs

std::vector<double> TrueRobot() { return {0.042 * 1.004, 0.042 * 0.996, 0.206}; }

std::vector<AlignedRun> Aligned(const std::vector<sim::ModelSimulatedRun>& runs) {
  std::vector<RunLog> logs;
  for (const auto& r : runs) logs.push_back(r.log);
  return AlignRuns(logs);
}

TEST(DiffDriveModel, AutodiffMatchesCentralDifferences) {
  const RobotModelPtr model = ModelFromYaml(kDiffDriveExampleYaml);
  const auto runs = Aligned(sim::SimulateRuns(
      *model, TrueRobot(), {sim::UmbmarkSquare(true, 1), sim::CircleTrajectory(0.5, false, 1)},
      sim::SimulationOptions{}));
  const std::vector<double> p = {0.0425, 0.0418, 0.203};
  // h = 1e-7 m: truncation O(h^2 f''') and rounding O(1e-16 / h) both < 1e-8 relative.
  for (const AlignedRun& run : runs) {
    testing::ExpectFinalPoseJacobianMatchesCentralDifferences(*model, run, p, 1e-7);
  }
}

TEST(ModelSimulator, RampsKeepTheSegmentsAndTheEncodersReplayTheTruth) {
  const RobotModelPtr model = ModelFromYaml(kDiffDriveExampleYaml);
  sim::DiffDriveTrajectoryOptions shape;
  shape.square_side_m = 1.5;
  const auto runs =
      sim::SimulateRuns(*model, TrueRobot(),
                        {sim::UmbmarkSquare(false, 1, shape), sim::CircleTrajectory(0.7, true, 1)},
                        sim::SimulationOptions{});
  for (const auto& run : runs) {
    SCOPED_TRACE(run.log.id);
    // The true robot follows the commanded twists and every ramp keeps its segment's integral:
    // the square and the full circle close exactly (only rounding remains).
    EXPECT_NEAR(run.true_final_pose.x, 0.0, 1e-9);
    EXPECT_NEAR(run.true_final_pose.y, 0.0, 1e-9);
    EXPECT_NEAR(std::abs(run.true_final_pose.theta), 2.0 * M_PI, 1e-9);
    // The encoders hold the exact wheel-angle advance per interval; replayed with the true
    // parameters they reach the truth up to the 50 ms steps' constant-rate assumption during the
    // ramps (rates change within an interval; < 0.1 mm measured, 1 mm allowed).
    const Pose2d replayed =
        model->ReplayFinalPose(TrueRobot().data(), run.log.encoders.samples, run.true_start_pose);
    EXPECT_NEAR(replayed.x, run.true_final_pose.x, 1e-3);
    EXPECT_NEAR(replayed.y, run.true_final_pose.y, 1e-3);
    EXPECT_NEAR(replayed.theta, run.true_final_pose.theta, 1e-9);
    EXPECT_EQ(run.log.ground_truth.t_s.front(), 0.0);
    EXPECT_NEAR(run.log.ground_truth.t_s.back(), run.log.encoders.t_s.back(), 1e-12);
  }
}

TEST(ModelSimulator, QuantisationNoiseAndSeeds) {
  const RobotModelPtr model = ModelFromYaml(kDiffDriveExampleYaml);
  sim::SimulationOptions o;
  o.ticks_per_rev = {1000.0, 1000.0};
  o.gt_position_sigma_m = 0.001;
  o.wheel_rate_sigma_rad_s = 0.01;
  o.seed = 7;
  const std::vector<sim::TrajectorySpec> specs = {sim::CircleTrajectory(0.5, false, 1)};
  const auto a = sim::SimulateRuns(*model, TrueRobot(), specs, o);
  const auto b = sim::SimulateRuns(*model, TrueRobot(), specs, o);
  EXPECT_EQ(a[0].log.encoders.samples, b[0].log.encoders.samples);  // same seed, same bits
  o.seed = 8;
  const auto c = sim::SimulateRuns(*model, TrueRobot(), specs, o);
  EXPECT_FALSE(a[0].log.encoders.samples == c[0].log.encoders.samples);
  // Every interval holds a whole number of ticks.
  for (const auto& s : a[0].log.encoders.samples) {
    for (int i = 0; i < 2; ++i) {
      const double ticks = s.value[i] * s.dt_s * 1000.0 / (2.0 * M_PI);
      EXPECT_NEAR(ticks, std::round(ticks), 1e-6);
    }
  }
  sim::SimulationOptions bad;
  bad.ticks_per_rev = {1000.0};
  EXPECT_THROW(sim::SimulateRuns(*model, TrueRobot(), specs, bad), std::invalid_argument);
  // A differential drive cannot move sideways.
  EXPECT_THROW(sim::SimulateRuns(*model, TrueRobot(), {{"side", 1, {{{0.0, 0.1, 0.0}, 2.0}}}},
                                 sim::SimulationOptions{}),
               std::invalid_argument);
}

TEST(ModelSimulator, WritesADataSetTheLoadersReadBack) {
  testing::TempDir dir;
  const RobotModelPtr model = ModelFromYaml(kDiffDriveExampleYaml);
  sim::SimulationOptions o;
  o.gt_position_sigma_m = 0.001;
  const auto runs = sim::SimulateRuns(*model, TrueRobot(), {sim::UmbmarkSquare(true, 3)}, o);
  sim::WriteSimulatedDataset(dir.Path("set"), model->RobotYaml(TrueRobot(), ""), runs);
  const YAML::Node index = YAML::LoadFile(dir.Path("set/dataset.yaml"));
  ASSERT_EQ(index["runs"].size(), 1u);
  EXPECT_EQ(index["runs"][0]["id"].as<std::string>(), "square-cw-rep03");
  EXPECT_EQ(index["runs"][0]["repetition"].as<int>(), 3);
  // Encoder CSV: the recorded rates at full precision.
  std::ifstream csv(dir.Path("set/runs/square-cw-rep03_encoders.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "t,w_right,w_left");
  std::size_t row = 0;
  while (std::getline(csv, line)) {
    const std::vector<double> t_right_left = testing::CsvNumbers(line, 3);
    ASSERT_EQ(t_right_left[0], runs[0].log.encoders.t_s[row]);
    if (row > 0) {
      ASSERT_EQ(t_right_left[1], runs[0].log.encoders.samples[row - 1].value[0]);
      ASSERT_EQ(t_right_left[2], runs[0].log.encoders.samples[row - 1].value[1]);
    }
    ++row;
  }
  EXPECT_EQ(row, runs[0].log.encoders.t_s.size());
  const GroundTruthTrack gt =
      io::ReadGroundTruth(dir.Path("set/runs/square-cw-rep03_ground_truth.csv"));
  ASSERT_EQ(gt.t_s.size(), runs[0].log.ground_truth.t_s.size());
  EXPECT_NEAR(gt.world_T_robot.back().x, runs[0].log.ground_truth.world_T_robot.back().x, 1e-6);
  const RobotModelPtr back = ReadRobotModelFile(dir.Path("set/robot.yaml"));
  EXPECT_NEAR(back->robot().nominal[2], TrueRobot()[2], 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Robot YAML

TEST(DiffDriveYaml, RoundTripKeepsValuesSidesAndBlocks) {
  for (const char* text : {kDiffDriveExampleYaml, kLeftFirstYaml}) {
    const RobotModelPtr model = ModelFromYaml(text);
    const Robot& robot = model->robot();
    ASSERT_EQ(robot.NumParameters(), 3);
    const std::vector<double> p = {robot.nominal[0] * 1.01, robot.nominal[1] * 0.99,
                                   robot.nominal[2] * 1.02};
    const std::string yaml = model->RobotYaml(p, "calibration:\n  method: test\n");
    const RobotModelPtr back = ModelFromYaml(yaml);
    EXPECT_EQ(DiffDriveRightChannel(*back), DiffDriveRightChannel(*model));
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(back->robot().parameters[k].name, robot.parameters[k].name);
      EXPECT_NEAR(back->robot().nominal[k], p[k], 1e-12);
      EXPECT_EQ(back->robot().bounds[k].lo, robot.bounds[k].lo);
      EXPECT_EQ(back->robot().bounds[k].hi, robot.bounds[k].hi);
    }
    EXPECT_EQ(back->robot().channels[0].ticks_column, robot.channels[0].ticks_column);
    EXPECT_EQ(back->robot().encoder.has_value(), robot.encoder.has_value());
    EXPECT_NE(yaml.find("calibration:\n  method: test"), std::string::npos);
  }
  const RobotModelPtr left_first = ModelFromYaml(kLeftFirstYaml);
  EXPECT_EQ(DiffDriveRightChannel(*left_first), 1);
  EXPECT_EQ(left_first->robot().parameters[0].name, "r_m1");
  EXPECT_EQ(left_first->robot().parameters[2].name, "wheel_separation");
  EXPECT_EQ(left_first->robot().channels[1].rate_column, "w_m2");
  EXPECT_EQ(DiffDriveRightChannel(*ModelFromYaml(kDiffDriveExampleYaml)), 0);
}

struct Malformed {
  const char* what;
  std::string from;  // replaced in kDiffDriveExampleYaml
  std::string to;
  io::InputErrorKind kind;
  int line;
};

TEST(DiffDriveYaml, MalformedRobotsAreOneLineInputErrors) {
  const std::string good = kDiffDriveExampleYaml;
  const std::string right = "  - {name: right, radius_m: 0.042}\n";
  const std::vector<Malformed> cases = {
      {"missing wheel", right, "", io::InputErrorKind::kBadValue, 4},
      {"extra wheel", right, right + "  - {name: third, side: left, radius_m: 0.042}\n",
       io::InputErrorKind::kBadValue, 4},
      {"separation outside bounds", "wheel_separation_m: 0.200", "wheel_separation_m: 0.250",
       io::InputErrorKind::kBadValue, 6},
      {"negative radius", "{name: right, radius_m: 0.042}", "{name: right, radius_m: -0.042}",
       io::InputErrorKind::kBadValue, 4},
      {"radius outside bounds", "{name: left, radius_m: 0.042}", "{name: left, radius_m: 0.050}",
       io::InputErrorKind::kBadValue, 5},
      {"zero separation", "wheel_separation_m: 0.200", "wheel_separation_m: 0.0",
       io::InputErrorKind::kBadValue, 6},
      {"unknown key", "name: example_diff_drive", "name: example_diff_drive\nwheel_base: 0.2",
       io::InputErrorKind::kUnknownKey, 0},
      {"unknown wheel key", "{name: left, radius_m: 0.042}",
       "{name: left, radius_m: 0.042, offset_m: 0.0}", io::InputErrorKind::kUnknownKey, 0},
      {"no side", "{name: left,", "{name: port,", io::InputErrorKind::kMissingKey, 5},
      {"two right wheels", "{name: left,", "{name: port, side: right,",
       io::InputErrorKind::kBadValue, 5},
      {"name contradicts side", "{name: left,", "{name: left, side: right,",
       io::InputErrorKind::kBadValue, 5},
      {"missing separation", "wheel_separation_m: 0.200\n", "", io::InputErrorKind::kMissingKey, 0},
      {"non-positive bounds", "radius_m: [0.038, 0.046]", "radius_m: [0.0, 0.046]",
       io::InputErrorKind::kBadValue, 7},
      // A wheel pair carries the pivot yaw gain (line 4), not a steering effect (line 5).
      {"steering effect", "name: example_diff_drive\n",
       "name: example_diff_drive\neffects:\n  - {name: pivot_yaw_gain, gain: 0.0}\n"
       "  - {name: steering_scale, scale: 0.01}\n",
       io::InputErrorKind::kBadValue, 5},
  };
  for (const Malformed& c : cases) {
    SCOPED_TRACE(c.what);
    std::string text = good;
    const std::size_t at = text.find(c.from);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, c.from.size(), c.to);
    try {
      ModelFromYaml(text);
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const io::InputError& e) {
      EXPECT_EQ(e.kind(), c.kind) << e.what();
      if (c.line > 0) {
        EXPECT_EQ(e.line(), c.line) << e.what();
      }
      EXPECT_EQ(e.file(), "robot.yaml");
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// UMBmark

// Worked example, by hand from Borenstein & Feng's equations (umbmark.h), L = 4 m, b = 0.5 m,
// r_R = r_L = 0.1 m, centres of gravity x_cw = -0.13, y_cw = -0.11, x_ccw = -0.04, y_ccw = 0.04 m:
//   alpha_x = (x_cw + x_ccw) / (-4L) = -0.17 / -16 = 0.010625,  alpha_y = (y_cw - y_ccw) / (-4L)
//   = -0.15 / -16 = 0.009375,  alpha = 0.01 rad;
//   beta_x = (x_cw - x_ccw) / (-4L) = 0.005625,  beta_y = (y_cw + y_ccw) / (-4L) = 0.004375,
//   beta = 0.005 rad;
//   R = 2 / sin(0.0025) = 800.000833333941 m,  E_d = (R + 0.25) / (R - 0.25) = 1.000625194722106,
//   E_b = 90 / (90 - 0.5729577951) = 1.006406985862489,  b' = 0.503203492931245 m,
//   r_R' = 0.2 / (1 / E_d + 1) = 0.100031249967448,  r_L' = 0.2 / (E_d + 1) = 0.099968750032552.
TEST(Umbmark, WorkedExampleFromThePapersEquations) {
  const std::vector<umbmark::SquareReturnError> runs = {{true, 4.0, -0.13, -0.11},
                                                        {false, 4.0, -0.04, 0.04}};
  const auto c = umbmark::Correct(runs, {0.1, 0.1, 0.5});
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->alpha_rad, 0.01, 1e-15);
  EXPECT_NEAR(c->beta_rad, 0.005, 1e-15);
  EXPECT_NEAR(c->e_d, 1.000625194722106, 1e-14);
  EXPECT_NEAR(c->e_b, 1.006406985862489, 1e-14);
  EXPECT_NEAR(c->corrected.separation_m, 0.503203492931245, 1e-14);
  EXPECT_NEAR(c->corrected.r_right_m, 0.100031249967448, 1e-14);
  EXPECT_NEAR(c->corrected.r_left_m, 0.099968750032552, 1e-14);
  // Centres of gravity of several runs give the same as the centroids themselves.
  const std::vector<umbmark::SquareReturnError> spread = {{true, 4.0, -0.12, -0.10},
                                                          {true, 4.0, -0.14, -0.12},
                                                          {false, 4.0, -0.05, 0.03},
                                                          {false, 4.0, -0.03, 0.05},
                                                          {false, 4.0, -0.04, 0.04}};
  const auto d = umbmark::Correct(spread, {0.1, 0.1, 0.5});
  ASSERT_TRUE(d.has_value());
  EXPECT_NEAR(d->e_b, c->e_b, 1e-14);
  EXPECT_NEAR(d->e_d, c->e_d, 1e-14);
  // One direction alone determines nothing.
  EXPECT_FALSE(umbmark::Correct({runs[0]}, {0.1, 0.1, 0.5}).has_value());
}

// A robot whose right wheel is 0.8 % larger than its left (mean kept) and whose separation is 3 %
// larger than nominal, driven around noise-free 1 m squares both ways. Its errors: beta =
// L (r_R - r_L) / (r b) = 0.04 rad per leg, alpha = pi/2 (1 - b_nom / b_true) = 0.046 rad per
// corner. UMBmark is first order in them: what it leaves is second order, ~ (alpha + beta) ~ 8 %
// of the error itself (measured: 6 % of the wheel-ratio error, 2.5 % of the separation error);
// 12 % allowed. A wrong sign would double the error instead.
TEST(Umbmark, RecoversASimulatedRobotFromNoiseFreeSquares) {
  const RobotModelPtr model = ModelFromYaml(kDiffDriveExampleYaml);
  const std::vector<double> truth = {0.042 * 1.004, 0.042 * 0.996, 0.206};
  std::vector<sim::TrajectorySpec> specs = {sim::UmbmarkSquare(true, 1),
                                            sim::UmbmarkSquare(false, 1),
                                            sim::CircleTrajectory(0.5, false, 1)};
  const auto runs = Aligned(sim::SimulateRuns(*model, truth, specs, sim::SimulationOptions{}));
  const std::vector<ClosedFormCalibration> closed = model->ClosedForms(runs);
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_EQ(closed[0].method, "umbmark");
  const std::vector<double>& p = closed[0].parameters;
  const std::vector<double>& nominal = model->robot().nominal;
  const double ratio_error_before = std::abs(nominal[0] / nominal[1] - truth[0] / truth[1]);
  const double ratio_error_after = std::abs(p[0] / p[1] - truth[0] / truth[1]);
  const double b_error_before = std::abs(nominal[2] - truth[2]);
  const double b_error_after = std::abs(p[2] - truth[2]);
  std::printf(
      "UMBmark left %.1f %% of the wheel-ratio error and %.1f %% of the separation "
      "error (%s)\n",
      100.0 * ratio_error_after / ratio_error_before, 100.0 * b_error_after / b_error_before,
      closed[0].note.c_str());
  EXPECT_LT(ratio_error_after, 0.12 * ratio_error_before) << closed[0].note;
  EXPECT_LT(b_error_after, 0.12 * b_error_before) << closed[0].note;
  EXPECT_NEAR(p[0] + p[1], nominal[0] + nominal[1], 1e-15);  // the mean radius is kept
  // Squares of one direction only: no UMBmark.
  EXPECT_TRUE(model->ClosedForms({runs[0], runs[2]}).empty());
}

// ---------------------------------------------------------------------------------------------
// The Ceres fit on simulated data

// Ground truth noisy at the final pose only (the start pose is recorded), 1 mm per axis and
// 0.2 deg: with the residual whitened by those sigmas the fit's covariance (J^T J)^-1 is the
// parameters' own, and s^2 must be ~1. Squares and circles close on themselves, so the scale
// (mean radius with the separation) shows only in their open counterparts: three-quarter
// circles and the open arc of a 1.25-lap circle are added.
TEST(DiffDriveFit, RecoversASimulatedRobotWithinItsSigmas) {
  const RobotModelPtr model = ModelFromYaml(kDiffDriveExampleYaml);
  const std::vector<double> truth = TrueRobot();
  sim::DiffDriveTrajectoryOptions open;
  open.circle_laps = 0.75;
  std::vector<sim::TrajectorySpec> specs;
  for (int rep = 1; rep <= 4; ++rep) {
    for (sim::TrajectorySpec s : sim::DiffDriveCalibrationTrajectories(1)) {
      s.repetition = rep;
      specs.push_back(s);
    }
    for (double r : {0.4, 0.8}) {
      specs.push_back(sim::CircleTrajectory(r, rep % 2 == 0, rep, open));
    }
  }
  sim::SimulationOptions o;
  o.gt_position_sigma_m = 0.001;
  o.gt_heading_sigma_rad = 0.2 * M_PI / 180.0;
  o.record_start_pose = true;
  o.seed = 11;
  const auto runs = Aligned(sim::SimulateRuns(*model, truth, specs, o));
  ModelFitOptions options;
  options.ceres.weights = {o.gt_position_sigma_m, o.gt_heading_sigma_rad};
  const ModelFitResult fit = FitModel(runs, *model, options);
  ASSERT_TRUE(fit.usable) << fit.termination << ": " << fit.message;
  ASSERT_TRUE(fit.has_covariance) << fit.covariance_message;
  std::printf(
      "fit: s = %.3f; r_R %.7f +- %.7f (true %.7f), r_L %.7f +- %.7f (true %.7f), b %.6f +- "
      "%.6f (true %.6f)\n",
      fit.residual_sigma, fit.parameters[0], fit.sigma[0], truth[0], fit.parameters[1],
      fit.sigma[1], truth[1], fit.parameters[2], fit.sigma[2], truth[2]);
  // s^2 ~ chi^2 / dof with dof = 3 N - 3 ~ 90: 0.7 < s < 1.3 is beyond 3 sigma of it.
  EXPECT_GT(fit.residual_sigma, 0.7);
  EXPECT_LT(fit.residual_sigma, 1.3);
  for (int k = 0; k < 3; ++k) {
    const double sigma = fit.sigma[k];
    EXPECT_LT(std::abs(fit.parameters[k] - truth[k]), 4.0 * sigma)
        << model->robot().parameters[k].name << " sigma " << sigma;
    // The test can fail: the nominal is many sigmas from the truth.
    EXPECT_GT(std::abs(model->robot().nominal[k] - truth[k]), 10.0 * sigma);
  }
}

// ---------------------------------------------------------------------------------------------
// Real data: OptiOdom's differential drive

const fs::path kDiff = fs::path(FITCAL_SHARED_DIR) / "data" / "optiodom" / "diff";
const fs::path kFlaggedSession = kDiff / "square" / "231220200029";
const fs::path kCircleSession = kDiff / "circular" / "250620202104";

// Nominal odometry by hand from the published run file: wheel distance pi D ticks / (ngear
// encRes), constant wheel speeds over each 50 ms cycle (exact arc: chord of length
// s sinc(dtheta/2) in the direction dtheta/2), b and D from the session's metadata (0.2 m,
// 0.084 m). Returns (x, y, theta) odometry minus ground truth at the last row.
std::array<double, 3> HandFinalError(const fs::path& run_csv) {
  const double b = 0.2, d = 0.084, ticks_per_rev = 43.7 * 64.0;
  std::ifstream in(run_csv);
  std::string line;
  double x = 0.0, y = 0.0, theta = 0.0, gt[3] = {0.0, 0.0, 0.0};
  bool first = true;
  while (std::getline(in, line)) {
    const std::vector<double> v = testing::CsvNumbers(line, 6);
    gt[0] = v[1], gt[1] = v[2], gt[2] = v[3];
    if (first) {
      first = false;
      continue;
    }
    const double d_right = M_PI * d * v[4] / ticks_per_rev;
    const double d_left = M_PI * d * v[5] / ticks_per_rev;
    const double s = 0.5 * (d_right + d_left), a = (d_right - d_left) / b;
    const double chord = std::abs(a) < 1e-9 ? s : s * std::sin(0.5 * a) / (0.5 * a);
    x += chord * std::cos(theta + 0.5 * a);
    y += chord * std::sin(theta + 0.5 * a);
    theta += a;
  }
  return {x - gt[0], y - gt[1], theta - gt[2]};
}

// The data set's encoder CSV `t,ticks_right,ticks_left` as the run log the loader would make.
EncoderLog ReadTicksCsv(const std::string& path, double ticks_per_rev) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "t,ticks_right,ticks_left");
  EncoderLog log;
  log.samples = EncoderSamples(2);
  while (std::getline(in, line)) {
    const std::vector<double> v = testing::CsvNumbers(line, 3);
    if (!log.t_s.empty()) {
      const double dt = v[0] - log.t_s.back();
      const double k = 2.0 * M_PI / ticks_per_rev / dt;
      log.samples.push_back(dt, {k * v[1], k * v[2]});
    }
    log.t_s.push_back(v[0]);
  }
  return log;
}

TEST(OptiOdomDiffImport, ReproducesTheNominalFinalErrorsOfRealSessions) {
  if (!fs::is_directory(kFlaggedSession) || !fs::is_directory(kCircleSession)) {
    GTEST_SKIP() << "no " << kDiff;
  }
  testing::TempDir dir;
  optiodom::ImportOptiOdomOptions options;
  options.sessions = {kFlaggedSession.string(), kCircleSession.string()};
  options.out = dir.Path("diff");
  const auto summary = optiodom::ImportOptiOdom(options);
  // 6 + 6 runs, the flagged square run 02 left out and said so.
  EXPECT_EQ(summary.runs.size(), 11u);
  ASSERT_EQ(summary.notes.size(), 1u);
  EXPECT_NE(summary.notes[0].find("square-231220200029-run02"), std::string::npos);
  const std::string index = testing::ReadFileBytes(dir.Path("diff/dataset.yaml"));
  EXPECT_NE(index.find("# left out square-231220200029-run02"), std::string::npos);
  EXPECT_EQ(index.find("id: square-231220200029-run02"), std::string::npos);

  const RobotModelPtr model = ReadRobotModelFile(dir.Path("diff/robot.yaml"));
  ASSERT_EQ(DiffDriveRightChannel(*model), 0);
  const std::vector<double>& p = model->robot().nominal;
  EXPECT_EQ(p, (std::vector<double>{0.042, 0.042, 0.2}));
  ASSERT_TRUE(model->robot().encoder.has_value());
  EXPECT_DOUBLE_EQ(model->robot().encoder->ticks_per_rev, 43.7 * 64.0);

  for (const auto& [session, run] : {std::pair{kFlaggedSession, 1}, std::pair{kFlaggedSession, 4},
                                     std::pair{kCircleSession, 2}}) {
    char name[64];
    std::snprintf(name, sizeof name, "_run-%02d.csv", run);
    const std::string s = session.filename().string();
    const auto hand = HandFinalError(session / (s + name));
    char id[96];
    std::snprintf(id, sizeof id, "%s-%s-run%02d", session.parent_path().filename().c_str(),
                  s.c_str(), run);
    SCOPED_TRACE(id);
    RunLog log;
    log.id = id;
    log.encoders = ReadTicksCsv(dir.Path(std::string("diff/runs/") + id + "_encoders.csv"),
                                model->robot().encoder->ticks_per_rev);
    log.ground_truth =
        io::ReadGroundTruth(dir.Path(std::string("diff/runs/") + id + "_ground_truth.csv"));
    const AlignedRun aligned = AlignRun(log);
    double r[3];
    FinalPoseError(model->ReplayFinalPose(p.data(), aligned.samples, aligned.start),
                   aligned.final_ground_truth, ResidualWeights{}, r);
    // Ground truth written with 6 decimals (5e-7 m): 1e-6 m and 1e-6 rad hold.
    EXPECT_NEAR(r[0], hand[0], 1e-6);
    EXPECT_NEAR(r[1], hand[1], 1e-6);
    EXPECT_NEAR(r[2], hand[2], 1e-6);
    // Centimetres, not millimetres: the nominal robot is visibly off (the test sees data).
    EXPECT_GT(std::hypot(hand[0], hand[1]), 0.01);
  }
}

// Every shared session: what the importer reports, and the measured numbers this robot gives
// (printed for the README). Trained on odd repetitions, held out on even ones.
std::vector<AlignedRun> Select(const std::vector<AlignedRun>& runs, bool odd,
                               const std::string& label_part = "") {
  std::vector<AlignedRun> out;
  for (const AlignedRun& r : runs) {
    if ((r.repetition % 2 == 1) == odd && r.trajectory.find(label_part) != std::string::npos) {
      out.push_back(r);
    }
  }
  return out;
}

TEST(OptiOdomDiffImport, EverySessionNominalUmbmarkAndFit) {
  if (!fs::is_directory(kDiff / "circular") || !fs::is_directory(kDiff / "square")) {
    GTEST_SKIP() << "no " << kDiff;
  }
  std::vector<std::string> sessions;
  for (const char* type : {"circular", "square"}) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(kDiff / type)) names.push_back(e.path().string());
    std::sort(names.begin(), names.end());
    sessions.insert(sessions.end(), names.begin(), names.end());
  }
  testing::TempDir dir;
  optiodom::ImportOptiOdomOptions options;
  options.sessions = sessions;
  options.out = dir.Path("diff");
  const auto summary = optiodom::ImportOptiOdom(options);
  // README: 13 + 8 sessions, 54 + 44 runs, one flagged; four sessions declare perturbed values.
  EXPECT_EQ(summary.num_sessions, 21);
  EXPECT_EQ(summary.runs.size(), 97u);
  EXPECT_EQ(summary.notes.size(), 5u);
  for (const std::string& n : summary.notes) std::printf("  note: %s\n", n.c_str());
  const RobotModelPtr model = ReadRobotModelFile(dir.Path("diff/robot.yaml"));
  const std::vector<AlignedRun> all = AlignRuns(summary.runs);
  const auto cf = [&](const std::vector<double>& p, const std::vector<AlignedRun>& runs) {
    return EvaluateFinalPoseErrors(*model, p, runs);
  };
  const std::vector<double>& nominal = model->robot().nominal;
  std::printf(
      "nominal CF all %.4f (mean position %.4f m, heading %.3f deg); circles %.4f, "
      "squares %.4f\n",
      summary.nominal.cf, summary.nominal.mean_position_error_m,
      summary.nominal.mean_abs_heading_error_rad * 180.0 / M_PI,
      cf(nominal, Select(all, true, "circular")).cf, cf(nominal, Select(all, true, "square")).cf);
  // UMBmark from all squares, and from one square session at a time, scored on every circle.
  std::vector<AlignedRun> circles;
  for (const AlignedRun& r : all) {
    if (r.trajectory.rfind("circular", 0) == 0) circles.push_back(r);
  }
  const auto umbmark_all = model->ClosedForms(all);
  ASSERT_EQ(umbmark_all.size(), 1u);
  std::printf(
      "UMBmark (all squares): r_R %.6f r_L %.6f b %.6f; CF circles %.4f (nominal %.4f)\n"
      "  %s\n",
      umbmark_all[0].parameters[0], umbmark_all[0].parameters[1], umbmark_all[0].parameters[2],
      cf(umbmark_all[0].parameters, circles).cf, cf(nominal, circles).cf,
      umbmark_all[0].note.c_str());
  std::map<std::string, std::vector<AlignedRun>> by_session;
  for (const AlignedRun& r : all) {
    if (r.trajectory.rfind("square", 0) == 0) by_session[r.trajectory].push_back(r);
  }
  for (const auto& [session, runs] : by_session) {
    const auto u = model->ClosedForms(runs);
    if (u.empty()) continue;
    std::printf("  UMBmark %s: b %.5f r_R/r_L %.5f, CF circles %.4f\n", session.c_str(),
                u[0].parameters[2], u[0].parameters[0] / u[0].parameters[1],
                cf(u[0].parameters, circles).cf);
  }
  // The fit: trained on odd repetitions of circles and squares, held out on even ones.
  const std::vector<AlignedRun> train = Select(all, true), held_out = Select(all, false);
  const auto t0 = std::chrono::steady_clock::now();
  const ModelFitResult fit = FitModel(train, *model);
  const double fit_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(fit.usable) << fit.termination << ": " << fit.message;
  const FinalPoseErrors before = cf(nominal, held_out), after = cf(fit.parameters, held_out);
  const FinalPoseErrors umb = cf(umbmark_all[0].parameters, held_out);
  std::printf(
      "fit (%zu training runs, %.3f s): r_R %.6f +- %.6f, r_L %.6f +- %.6f, b %.6f +- "
      "%.6f\nheld out (%zu runs): CF nominal %.4f, UMBmark %.4f, fit %.4f; mean position "
      "%.4f -> %.4f m, heading %.3f -> %.3f deg\n",
      train.size(), fit_s, fit.parameters[0], fit.sigma[0], fit.parameters[1], fit.sigma[1],
      fit.parameters[2], fit.sigma[2], held_out.size(), before.cf, umb.cf, after.cf,
      before.mean_position_error_m, after.mean_position_error_m,
      before.mean_abs_heading_error_rad * 180.0 / M_PI,
      after.mean_abs_heading_error_rad * 180.0 / M_PI);
  EXPECT_LT(after.cf, 0.5 * before.cf);
  for (int k = 0; k < 3; ++k) EXPECT_FALSE(fit.at_bound[k]) << model->robot().parameters[k].name;

  // Against the method published with these recordings (Sousa et al.'s OptiOdom cost, position
  // from the start every 0.5 m; validation/generalisation.h) on the same split: the README's
  // tables say the fit's final poses transfer better whenever circles train. Measured: 0.0309
  // against 0.0319 here (the data are fixed, so the margin is not noise; a change that loses it
  // must say so in the README).
  GeneralisationSplit split{"odd", "even", {}, {}};
  std::vector<std::vector<Segment>> checkpoints;
  for (std::size_t i = 0; i < all.size(); ++i) {
    (all[i].repetition % 2 == 1 ? split.train : split.test).push_back(i);
    checkpoints.push_back(MakeCheckpointsFromStart(all[i], summary.runs[i].ground_truth, 0.5));
  }
  const SplitScores scores =
      EvaluateSplit(*model, all, split, {}, TrackCandidates{&checkpoints, nullptr, {}});
  double fit_cf = -1.0, optiodom_cf = -1.0;
  for (const CandidateScore& c : scores.candidates) {
    if (c.name == "fit") fit_cf = c.test.cf;
    if (c.name == "optiodom") optiodom_cf = c.test.cf;
  }
  std::printf("held out (even repetitions): CF OptiOdom's method %.4f, fit %.4f\n", optiodom_cf,
              fit_cf);
  EXPECT_NEAR(fit_cf, after.cf, 1e-9);  // the same fit as above
  ASSERT_GT(optiodom_cf, 0.0);
  EXPECT_LT(optiodom_cf, 0.5 * before.cf);  // a real calibration ...
  EXPECT_LT(fit_cf, optiodom_cf);           // ... which the fit beats
}

// ---------------------------------------------------------------------------------------------
// What a recording in the wrong conventions looks like to the checks before fitting

RobotModelPtr EvenWheelsModel(const std::string& radius_bounds) {
  return ModelFromYaml(
      "model: diff_drive\nname: even\nwheels:\n  - {name: right, side: right, radius_m: 0.05}\n"
      "  - {name: left, side: left, radius_m: 0.05}\nwheel_separation_m: 0.3\nbounds: {radius_m: " +
      radius_bounds + ", wheel_separation_m: [0.27, 0.33]}\n");
}

// Three 40 s slaloms at 100 Hz whose ground truth is the model's own odometry, sampled at every
// encoder instant; `heading_offset` turns the ground truth's frame (pi: a sensor facing backwards).
std::vector<RunLog> ExactSlaloms(const RobotModelInterface& model, double heading_offset = 0.0) {
  std::vector<RunLog> logs(3);
  for (int r = 0; r < 3; ++r) {
    RunLog& log = logs[r];
    log.id = "slalom-" + std::to_string(r + 1);
    log.trajectory = "slalom";
    log.repetition = r + 1;
    log.encoders.samples = EncoderSamples(2);
    log.encoders.t_s = {0.0};
    for (int k = 1; k <= 4000; ++k) {
      const double t = 0.01 * k;
      log.encoders.samples.push_back(
          0.01, {4.0 + 2.0 * std::sin(0.3 * t + r), 4.0 + 2.0 * std::cos(0.2 * t)});
      log.encoders.t_s.push_back(t);
    }
    log.ground_truth.t_s = {0.0};
    log.ground_truth.world_T_robot = {Pose2d{0.0, 0.0, heading_offset}};
    model.Replay(model.robot().nominal.data(), log.encoders.samples, 0, 4000, Pose2d{},
                 [&](std::size_t k, const Pose2d& pose) {
                   log.ground_truth.t_s.push_back(log.encoders.t_s[k + 1]);
                   log.ground_truth.world_T_robot.push_back(
                       Pose2d{pose.x, pose.y, pose.theta + heading_offset});
                 });
  }
  return logs;
}

ChannelMapping Mapping(std::vector<int> column, std::vector<int> sign) {
  ChannelMapping m;
  m.column = std::move(column);
  m.sign = std::move(sign);
  return m;
}

// Wheels swapped and both negated drive the body backwards: every step (dx, dy, dtheta) becomes
// (-dx, -dy, dtheta), the motion a ground truth facing backwards records. One wheel negated, or
// the two swapped, is another motion.
TEST(DiffDriveMiswiring, SwappedAndNegatedWheelsAreTheBodyTurnedHalfway) {
  const RobotModelPtr model = EvenWheelsModel("[0.045, 0.055]");
  const std::vector<AlignedRun> runs = AlignRuns(ExactSlaloms(*model));
  EXPECT_TRUE(TurnsTheBodyHalfway(*model, Mapping({1, 0}, {-1, -1}), runs));
  EXPECT_FALSE(TurnsTheBodyHalfway(*model, Mapping({0, 1}, {1, -1}), runs));
  EXPECT_FALSE(TurnsTheBodyHalfway(*model, Mapping({1, 0}, {1, 1}), runs));
}

// A pose sensor facing backwards (its frame 180 deg from the robot's forward) is explained
// exactly by the wheels swapped and negated: the refusal names both, so that a user with a rear
// camera declares its yaw instead of rewiring the robot (it named the wiring alone, and exported
// swapped, inverted joints when followed).
TEST(DiffDriveMiswiring, AGroundTruthFacingBackwardsIsNamedBesideTheWiring) {
  const RobotModelPtr model = EvenWheelsModel("[0.045, 0.055]");
  const std::vector<RunLog> logs = ExactSlaloms(*model, M_PI);
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : logs) tracks.push_back(&log.ground_truth);
  const ChannelOrderReport report = CheckRecordedChannelOrder(AlignRuns(logs), tracks, *model);
  ASSERT_TRUE(report.likely_miswired);
  EXPECT_NE(report.message.find("ground truth's frame faces backwards"), std::string::npos)
      << report.message;
  const std::vector<RunLog> forwards = ExactSlaloms(*model);
  tracks.clear();
  for (const RunLog& log : forwards) tracks.push_back(&log.ground_truth);
  EXPECT_FALSE(CheckRecordedChannelOrder(AlignRuns(forwards), tracks, *model).likely_miswired);
}

// Odometry that travels twice (or half) the ground truth's path, where the bounds let a radius
// change 10 % (ticks_per_rev declared for x2 decoding of an x4 encoder), is named before fitting
// (it was blamed on the wiring, or fitted to nothing); with bounds of 2x either way it is the
// fit's to find. Times in ms where s are meant are named as that.
TEST(DiffDriveUnits, TravelBeyondTheRadiusBoundsAndTimesInMillisecondsAreNamed) {
  const RobotModelPtr tight = EvenWheelsModel("[0.045, 0.055]");
  const std::vector<RunLog> exact = ExactSlaloms(*tight);
  EXPECT_FALSE(CheckModelRateUnits(*tight, exact).suspicious);
  for (const double factor : {2.0, 0.5}) {
    std::vector<RunLog> scaled = exact;
    for (RunLog& log : scaled) {
      for (auto&& s : log.encoders.samples) s.value[0] *= factor, s.value[1] *= factor;
    }
    const RateUnitsFinding finding = CheckModelRateUnits(*tight, scaled);
    EXPECT_TRUE(finding.suspicious) << factor;
    EXPECT_NE(finding.message.find("encoder.ticks_per_rev"), std::string::npos) << finding.message;
    EXPECT_FALSE(CheckModelRateUnits(*EvenWheelsModel("[0.025, 0.1]"), scaled).suspicious);
  }
  std::vector<RunLog> in_ms = exact;
  for (RunLog& log : in_ms) {
    for (double& t : log.encoders.t_s) t *= 1000.0;
    for (auto&& s : log.encoders.samples) s.dt_s *= 1000.0;
    for (double& t : log.ground_truth.t_s) t *= 1000.0;
  }
  const RateUnitsFinding ms = CheckModelRateUnits(*tight, in_ms);
  EXPECT_EQ(ms.likely_unit, "ms") << ms.message;
}

}  // namespace
}  // namespace fitcal
