// A pose source on a mount (models/mounted_model.h): the robot YAML's ground_truth_frame adds
// three parameters to any model; the sensor's replay is checked against the base's replay moved
// by the mount (S = B X, composed here independently), the residuals' Jacobians against central
// differences, and the YAML against a round trip and its malformed forms.

#include "models/mounted_model.h"

#include <ceres/cost_function.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "io/input_error.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "models/omni/omni_model.h"
#include "models/tricycle/tricycle_model.h"
#include "odometry/aligned_run.h"

namespace fitcal {
namespace {

constexpr const char* kFrame = "ground_truth_frame: {x_m: 1.5, y_m: -0.2, yaw_deg: 5.0}\n";

RobotModelPtr Read(const std::string& yaml) {
  return ReadRobotModel(YAML::Load(yaml), "robot.yaml");
}

// world_T_sensor = world_T_base base_T_sensor, written out.
Pose2d Times(const Pose2d& a, const Pose2d& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, a.theta + b.theta};
}
Pose2d Inverse(const Pose2d& a) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, -a.theta};
}

// A tricycle's run of turns both ways at several steering angles, 100 intervals.
AlignedRun TricycleRun() {
  AlignedRun run;
  run.samples = EncoderSamples(2);
  for (int k = 0; k < 100; ++k) {
    const double values[2] = {8.0, 0.6 * std::sin(0.07 * k)};
    run.samples.push_back(0.05, values);
  }
  run.start = Pose2d{3.0, -1.0, 0.4};
  run.final_ground_truth = Pose2d{3.5, -0.2, 1.0};
  return run;
}

TEST(MountedModel, AddsThreeParametersNamedAndBoundedLikeAnyOther) {
  const RobotModelPtr model = Read(std::string(kTricycleExampleYaml) + kFrame);
  const Robot& robot = model->robot();
  ASSERT_EQ(robot.NumParameters(), 6);
  EXPECT_EQ(*ParameterIndex(robot, "ground_truth_x"), 3);
  EXPECT_EQ(*ParameterIndex(robot, "ground_truth_y"), 4);
  EXPECT_EQ(*ParameterIndex(robot, "ground_truth_yaw"), 5);
  EXPECT_DOUBLE_EQ(robot.nominal[3], 1.5);
  EXPECT_DOUBLE_EQ(robot.nominal[4], -0.2);
  EXPECT_DOUBLE_EQ(robot.nominal[5], DegToRad(5.0));
  EXPECT_TRUE(robot.bounds[3].Contains(1.5 - 1.9) && robot.bounds[3].Contains(1.5 + 1.9));
  EXPECT_TRUE(robot.held.empty()) << "a tricycle sees x, y and yaw of its pose source";
}

TEST(MountedModel, ReadsTheFramesBoundsUnderBounds) {
  const RobotModelPtr model = Read(
      "model: tricycle\nname: t\ntraction_wheel: {radius_m: 0.0325}\nwheelbase_m: 0.15\n"
      "steering_offset_deg: 0.0\nbounds: {radius_m: [0.030, 0.035], wheelbase_m: [0.13, 0.17], "
      "steering_offset_deg: [-10.0, 10.0], ground_truth_x_m: [1.0, 2.0], ground_truth_yaw_deg: "
      "[-10, 10]}\n" +
      std::string(kFrame));
  const Robot& robot = model->robot();
  EXPECT_DOUBLE_EQ(robot.bounds[3].lo, 1.0);
  EXPECT_DOUBLE_EQ(robot.bounds[3].hi, 2.0);
  EXPECT_DOUBLE_EQ(robot.bounds[5].hi, DegToRad(10.0));
  EXPECT_DOUBLE_EQ(robot.bounds[4].lo, -0.2 - 2.0);  // the default
}

TEST(MountedModel, AnOmniRobotsXAndYAreHeldWithTheReason) {
  const Robot robot = Read(std::string(kOmniExampleYaml) + kFrame)->robot();
  const int x = *ParameterIndex(robot, "ground_truth_x");
  ASSERT_TRUE(robot.IsHeld(x));
  ASSERT_TRUE(robot.IsHeld(x + 1));
  EXPECT_FALSE(robot.IsHeld(x + 2));
  for (const HeldParameter& h : robot.held) {
    if (h.index == x) {
      EXPECT_NE(h.reason.find("wheel distances"), std::string::npos) << h.reason;
    }
  }
  EXPECT_TRUE(Read(std::string(kDiffDriveExampleYaml) + kFrame)->robot().held.empty());
}

TEST(MountedModel, RefusesAMalformedFrameWithFileAndLine) {
  const std::string base = kDiffDriveExampleYaml;
  const auto message = [&](const std::string& yaml) {
    try {
      Read(yaml);
    } catch (const io::InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message(base + "ground_truth_frame: {x_m: 1.5, y_m: 0.0}\n").find("robot.yaml:8"),
            std::string::npos);
  EXPECT_NE(message(base + "ground_truth_frame: {x_m: 1, y_m: 0, yaw_deg: 0, z_m: 1}\n")
                .find("z_m"),
            std::string::npos);
  EXPECT_NE(message("model: diff_drive\nname: d\nwheels:\n  - {name: right, radius_m: 0.042}\n"
                    "  - {name: left, radius_m: 0.042}\nwheel_separation_m: 0.2\nbounds:\n"
                    "  radius_m: [0.038, 0.046]\n  wheel_separation_m: [0.18, 0.22]\n"
                    "  ground_truth_x_m: [2.0, 3.0]\n" +
                    std::string(kFrame))
                .find("robot.yaml:10"),
            std::string::npos);
}

// The sensor's poses are the base's, replayed from S_0 X^-1, times X: at every sample.
TEST(MountedModel, ReplaysTheSensorAsTheBaseTimesTheMount) {
  const RobotModelPtr model = Read(std::string(kTricycleExampleYaml) + kFrame);
  const RobotModelInterface& base = BaseModel(*model);
  ASSERT_NE(&base, model.get());
  const AlignedRun run = TricycleRun();
  const std::vector<double>& p = model->robot().nominal;
  const Pose2d mount{p[3], p[4], p[5]};
  const Pose2d base_start = Times(run.start, Inverse(mount));
  std::vector<Pose2d> expected(run.samples.size());
  base.Replay(p.data(), run.samples, 0, run.samples.size(), base_start,
              [&](std::size_t k, const Pose2d& b) { expected[k] = Times(b, mount); });
  int checked = 0;
  const Pose2d last = model->Replay(
      p.data(), run.samples, 0, run.samples.size(), run.start, [&](std::size_t k, const Pose2d& s) {
        EXPECT_NEAR(s.x, expected[k].x, 1e-12);
        EXPECT_NEAR(s.y, expected[k].y, 1e-12);
        EXPECT_NEAR(s.theta, expected[k].theta, 1e-12);
        ++checked;
      });
  EXPECT_EQ(checked, 100);
  // The prepared kinematics (the effect replay's path) step the sensor to the same pose.
  const auto step = model->PrepareKinematics(p.data());
  Pose2d pose = run.start;
  for (std::size_t k = 0; k < run.samples.size(); ++k) {
    Pose2d d;
    step->Step(run.samples[k].value, run.samples[k].dt_s, &d.x, &d.y, &d.theta);
    pose = Times(pose, d);
  }
  EXPECT_NEAR(pose.x, last.x, 1e-9);
  EXPECT_NEAR(pose.y, last.y, 1e-9);
  EXPECT_NEAR(pose.theta, last.theta, 1e-12);
}

// Jacobians of both residuals against central differences in every parameter, the mount's
// included (step 1e-6: truncation ~1e-12, rounding ~1e-10 on residuals of order 1).
void ExpectJacobianMatchesDifferences(const ceres::CostFunction& cost, std::vector<double> p) {
  const int m = cost.num_residuals(), n = static_cast<int>(p.size());
  std::vector<double> r(m), jacobian(static_cast<std::size_t>(m) * n);
  const double* blocks[] = {p.data()};
  double* jacobians[] = {jacobian.data()};
  ASSERT_TRUE(cost.Evaluate(blocks, r.data(), jacobians));
  constexpr double kStep = 1e-6;
  for (int j = 0; j < n; ++j) {
    std::vector<double> hi(m), lo(m);
    const double keep = p[j];
    p[j] = keep + kStep;
    cost.Evaluate(blocks, hi.data(), nullptr);
    p[j] = keep - kStep;
    cost.Evaluate(blocks, lo.data(), nullptr);
    p[j] = keep;
    for (int i = 0; i < m; ++i) {
      EXPECT_NEAR(jacobian[i * n + j], (hi[i] - lo[i]) / (2 * kStep), 2e-5) << i << ", " << j;
    }
  }
}

TEST(MountedModel, ResidualJacobiansMatchCentralDifferences) {
  const RobotModelPtr model = Read(std::string(kTricycleExampleYaml) + kFrame);
  const AlignedRun run = TricycleRun();
  std::vector<Segment> segments = {{0, 40, Pose2d{0.5, 0.1, 0.2}, 0.5},
                                   {20, 100, Pose2d{1.0, -0.3, -0.4}, 1.0}};
  std::unique_ptr<ceres::CostFunction> final_pose(model->FinalPoseCost(run, ResidualWeights{}));
  std::unique_ptr<ceres::CostFunction> segment(
      model->SegmentCost(run, segments, ResidualWeights{0.01, 0.02}));
  ExpectJacobianMatchesDifferences(*final_pose, model->robot().nominal);
  ExpectJacobianMatchesDifferences(*segment, model->robot().nominal);
}

// A mounted diff drive keeps its analytic segment cost's promise (residuals the same to the bit
// with and without Jacobians), so the track residual's memo (fit/track_residual.h) serves it too.
TEST(MountedModel, SaysItsResidualsAreAlikeWhereTheInnerModelsAre) {
  const RobotModelPtr model = Read(std::string(kDiffDriveExampleYaml) + kFrame);
  ASSERT_TRUE(BaseModel(*model).SegmentResidualsAlikeWithJacobians());
  EXPECT_TRUE(model->SegmentResidualsAlikeWithJacobians());
  AlignedRun run;
  run.samples = EncoderSamples(2);
  for (int k = 0; k < 80; ++k) {
    const double values[2] = {5.0 + std::sin(0.1 * k), 3.0};
    run.samples.push_back(0.05, values);
  }
  const std::vector<Segment> segments = {{0, 40, Pose2d{0.5, 0.1, 0.2}, 0.5},
                                         {20, 80, Pose2d{1.0, -0.3, -0.4}, 1.0}};
  std::unique_ptr<ceres::CostFunction> cost(
      model->SegmentCost(run, segments, ResidualWeights{0.01, 0.02}));
  const int m = cost->num_residuals();
  std::vector<double> p = model->robot().nominal;
  p[0] *= 1.01;
  std::vector<double> plain(m), with(m), jacobian(static_cast<std::size_t>(m) * p.size());
  const double* blocks[] = {p.data()};
  double* jacobians[] = {jacobian.data()};
  ASSERT_TRUE(cost->Evaluate(blocks, plain.data(), nullptr));
  ASSERT_TRUE(cost->Evaluate(blocks, with.data(), jacobians));
  EXPECT_EQ(std::memcmp(plain.data(), with.data(), m * sizeof(double)), 0);
}

// The final-pose residual is the sensor's replayed final pose minus the ground truth's.
TEST(MountedModel, FinalPoseResidualComparesTheSensorsPose) {
  const RobotModelPtr model = Read(std::string(kDiffDriveExampleYaml) + kFrame);
  AlignedRun run;
  run.samples = EncoderSamples(2);
  for (int k = 0; k < 50; ++k) {
    const double values[2] = {5.0, 3.0};
    run.samples.push_back(0.05, values);
  }
  run.start = Pose2d{1.0, 2.0, 0.3};
  const std::vector<double>& p = model->robot().nominal;
  const Pose2d sensor = model->ReplayFinalPose(p.data(), run.samples, run.start);
  run.final_ground_truth = Pose2d{sensor.x + 0.01, sensor.y - 0.02, sensor.theta + 0.03};
  std::unique_ptr<ceres::CostFunction> cost(model->FinalPoseCost(run, ResidualWeights{}));
  double r[3];
  const double* blocks[] = {p.data()};
  ASSERT_TRUE(cost->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], -0.01, 1e-12);
  EXPECT_NEAR(r[1], 0.02, 1e-12);
  EXPECT_NEAR(r[2], -0.03, 1e-12);
}

TEST(MountedModel, CalibratedYamlRoundTripsTheFrameAndItsBounds) {
  const RobotModelPtr model = Read(std::string(kTricycleExampleYaml) + kFrame);
  std::vector<double> p = model->robot().nominal;
  p[3] = 1.4;
  p[4] = -0.25;
  p[5] = DegToRad(4.0);
  const std::string yaml = model->RobotYaml(p, "calibration:\n  method: test\n");
  const RobotModelPtr back = Read(yaml);
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(back->robot().nominal[k], p[k], 1e-9) << yaml;
    EXPECT_NEAR(back->robot().bounds[k].lo, model->robot().bounds[k].lo, 1e-9) << yaml;
    EXPECT_NEAR(back->robot().bounds[k].hi, model->robot().bounds[k].hi, 1e-9) << yaml;
  }
  EXPECT_TRUE(YAML::Load(yaml)["calibration"]);
}

}  // namespace
}  // namespace fitcal
