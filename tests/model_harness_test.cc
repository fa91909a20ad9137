// The generic harness every registered robot model must pass (in the spirit of manif's
// MANIF_TEST_JACOBIANS): it runs over RegisteredModels(), each with its registry example robot,
// including the test-only unicycle of tests/models/unicycle_test_model.h, which proves that a
// model written entirely outside the library gets the seam.
//
//   1. autodiff Jacobian of the final-pose residual against central differences of the replay;
//   2. a constant-twist log replays the analytic arc (within the Euler bound of Eq. 4's step);
//   3. parameters -> robot YAML -> parameters round trip;
//   4. every candidate miswiring changes what the data show (a swapped or sign-flipped channel is
//      caught);
//   5. the generic bounded fit recovers the true free parameters from noise-free runs.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <vector>

#include "diagnosis/channel_order_check.h"
#include "fit/model_fit.h"
#include "models/model_registry.h"
#include "models/pose_errors.h"
#include "odometry/aligned_run.h"
#include "tests/model_support.h"
#include "tests/models/unicycle_test_model.h"

namespace fitcal {
namespace model_harness_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

constexpr double kDt = 0.01;
constexpr int kSamplesPerRun = 300;  // 3 s per run

// Motions every model is asked to drive; each model drives those it can.
const std::vector<Twist>& Motions() {
  static const std::vector<Twist> motions = {{0.3, 0.0, 0.0},  {0.3, 0.0, 0.5},   {0.25, 0.0, -0.8},
                                             {-0.2, 0.0, 0.3}, {0.0, 0.0, 0.9},   {0.2, 0.2, 0.4},
                                             {0.0, 0.3, 0.0},  {0.15, -0.1, -0.6}};
  return motions;
}

// The nominal moved `fraction` of the way to each upper bound (held parameters stay).
std::vector<double> Shifted(const Robot& robot, double fraction) {
  std::vector<double> p = robot.nominal;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (!robot.IsHeld(k)) p[k] += fraction * (robot.bounds[k].hi - p[k]);
  }
  return p;
}

// One run per drivable motion: channels commanded with the nominal, ground truth replayed with
// `truth`, from the origin.
std::vector<AlignedRun> SyntheticRuns(const RobotModelInterface& model,
                                      const std::vector<double>& truth) {
  const Robot& robot = model.robot();
  std::vector<AlignedRun> runs;
  std::vector<double> values(robot.NumChannels());
  for (const Twist& twist : Motions()) {
    if (!model.ChannelsForTwist(robot.nominal.data(), twist, values.data())) continue;
    AlignedRun run;
    run.id = "motion" + std::to_string(runs.size());
    run.samples = EncoderSamples(robot.NumChannels());
    for (int k = 0; k < kSamplesPerRun; ++k) run.samples.push_back(kDt, values.data());
    run.t_final_s = kSamplesPerRun * kDt;
    run.final_ground_truth = model.ReplayFinalPose(truth.data(), run.samples, run.start);
    runs.push_back(std::move(run));
  }
  return runs;
}

TEST(ModelHarness, EveryModelHasAnExampleThatParses) {
  ASSERT_NE(FindModel("test_unicycle"), nullptr);
  for (const ModelRegistration& m : RegisteredModels()) {
    SCOPED_TRACE(m.name);
    ASSERT_FALSE(m.example_yaml.empty());
    const RobotModelPtr model = testing::ExampleModel(m.name);
    const Robot& robot = model->robot();
    EXPECT_EQ(robot.model, m.name);
    EXPECT_EQ(static_cast<int>(robot.nominal.size()), robot.NumParameters());
    EXPECT_EQ(static_cast<int>(robot.bounds.size()), robot.NumParameters());
    EXPECT_GE(SyntheticRuns(*model, robot.nominal).size(), 3u) << "too few drivable motions";
  }
}

TEST(ModelHarness, AutodiffMatchesCentralDifferences) {
  for (const ModelRegistration& m : RegisteredModels()) {
    SCOPED_TRACE(m.name);
    const RobotModelPtr model = testing::ExampleModel(m.name);
    const Robot& robot = model->robot();
    const std::vector<double> p = Shifted(robot, 0.3);
    for (const AlignedRun& run : SyntheticRuns(*model, Shifted(robot, 0.6))) {
      testing::ExpectFinalPoseJacobianMatchesCentralDifferences(*model, run, p);
    }
  }
}

// Pose after time t of a constant body twist from the origin (exact arc).
Pose2d ArcAfter(const Twist& v, double t) {
  const double a = v.omega_rad_s * t;
  const double s = std::abs(a) < 1e-12 ? t : std::sin(a) / v.omega_rad_s;
  const double c = std::abs(a) < 1e-12 ? 0.0 : (1.0 - std::cos(a)) / v.omega_rad_s;
  return {s * v.vx_m_s - c * v.vy_m_s, c * v.vx_m_s + s * v.vy_m_s, a};
}

TEST(ModelHarness, ConstantTwistReplaysTheAnalyticArc) {
  constexpr double kFineDt = 1e-3;
  constexpr int kSteps = 2000;
  for (const ModelRegistration& m : RegisteredModels()) {
    SCOPED_TRACE(m.name);
    const RobotModelPtr model = testing::ExampleModel(m.name);
    const Robot& robot = model->robot();
    std::vector<double> values(robot.NumChannels());
    for (const Twist& twist : Motions()) {
      if (!model->ChannelsForTwist(robot.nominal.data(), twist, values.data())) continue;
      EncoderSamples samples(robot.NumChannels());
      for (int k = 0; k < kSteps; ++k) samples.push_back(kFineDt, values.data());
      const Pose2d replayed = model->ReplayFinalPose(robot.nominal.data(), samples, Pose2d{});
      const Pose2d arc = ArcAfter(twist, kSteps * kFineDt);
      // Eq. 4 steps along the tangent at the start of each interval: the chord misses the arc by
      // |v| |omega| dt / 2 per unit time, so by |v| |omega| dt T / 2 after T.
      const double speed = std::hypot(twist.vx_m_s, twist.vy_m_s);
      const double bound = speed * std::abs(twist.omega_rad_s) * kFineDt * kSteps * kFineDt / 2.0;
      EXPECT_NEAR(replayed.x, arc.x, bound + 1e-9);
      EXPECT_NEAR(replayed.y, arc.y, bound + 1e-9);
      EXPECT_NEAR(replayed.theta, arc.theta, 1e-9);
    }
  }
}

TEST(ModelHarness, ParametersRoundTripThroughTheRobotYaml) {
  for (const ModelRegistration& m : RegisteredModels()) {
    SCOPED_TRACE(m.name);
    const RobotModelPtr model = testing::ExampleModel(m.name);
    const std::vector<double> p = Shifted(model->robot(), 0.4);
    const std::string text = model->RobotYaml(p, "");
    const RobotModelPtr back = ReadRobotModel(YAML::Load(text), "round trip");
    ASSERT_EQ(back->robot().NumParameters(), model->robot().NumParameters());
    for (int k = 0; k < model->robot().NumParameters(); ++k) {
      EXPECT_EQ(back->robot().parameters[k].name, model->robot().parameters[k].name);
      // The YAML keeps 10 significant digits.
      EXPECT_NEAR(back->robot().nominal[k], p[k], 1e-9 * std::abs(p[k]) + 1e-12);
    }
  }
}

// The effects a calibration carries are written with it and read back (a fit may refit, add or
// drop them, so they are given, not taken from the robot): every model, with an effect every
// model's channels can show.
TEST(ModelHarness, EffectsRoundTripThroughTheRobotYaml) {
  effects::EffectValue latency;
  latency.id = effects::EffectId::kTimeOffset;
  latency.value[0] = 0.0123456789;
  latency.sigma[0] = 0.0011;
  for (const ModelRegistration& m : RegisteredModels()) {
    SCOPED_TRACE(m.name);
    const RobotModelPtr model = testing::ExampleModel(m.name);
    ASSERT_TRUE(model->robot().effects.empty());
    const RobotModelPtr back =
        ReadRobotModel(YAML::Load(model->RobotYaml(model->robot().nominal, {latency}, "")), "rt");
    ASSERT_EQ(back->robot().effects.size(), 1u);
    EXPECT_EQ(back->robot().effects[0].id, latency.id);
    EXPECT_NEAR(back->robot().effects[0].value[0], latency.value[0], 1e-12);
    const RobotModelPtr none = ReadRobotModel(
        YAML::Load(back->RobotYaml(back->robot().nominal, {}, "")), "without effects");
    EXPECT_TRUE(none->robot().effects.empty());
  }
}

TEST(ModelHarness, EveryMiswiringChangesTheFinalPoses) {
  for (const ModelRegistration& m : RegisteredModels()) {
    SCOPED_TRACE(m.name);
    const RobotModelPtr model = testing::ExampleModel(m.name);
    const Robot& robot = model->robot();
    const std::vector<AlignedRun> runs = SyntheticRuns(*model, robot.nominal);
    const std::vector<ChannelMapping> mappings = model->CandidateMiswirings();
    ASSERT_FALSE(mappings.empty());
    EXPECT_TRUE(mappings.front().IsIdentity());
    for (std::size_t j = 1; j < mappings.size(); ++j) {
      double ssr = 0.0;
      for (const AlignedRun& run : ApplyChannelMapping(runs, mappings[j])) {
        double r[3];
        const Pose2d f = model->ReplayFinalPose(robot.nominal.data(), run.samples, run.start);
        FinalPoseError(f, run.final_ground_truth, ResidualWeights{}, r);
        ssr += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
      }
      // The recorded wiring explains these noise-free runs exactly; any other must leave at
      // least a millimetre (or milliradian) somewhere.
      EXPECT_GT(ssr, 1e-6) << "mapping " << j << " is indistinguishable from the identity";
    }
  }
}

TEST(ModelHarness, BoundedFitRecoversTheTruthFromNoiseFreeRuns) {
  for (const ModelRegistration& m : RegisteredModels()) {
    SCOPED_TRACE(m.name);
    const RobotModelPtr model = testing::ExampleModel(m.name);
    const Robot& robot = model->robot();
    const std::vector<double> truth = Shifted(robot, 0.5);
    const ModelFitResult fit = FitModel(SyntheticRuns(*model, truth), *model);
    ASSERT_TRUE(fit.usable) << fit.termination << ": " << fit.message;
    for (int k = 0; k < robot.NumParameters(); ++k) {
      EXPECT_NEAR(fit.parameters[k], truth[k], 1e-6 * robot.parameters[k].RelativeScale(truth[k]))
          << robot.parameters[k].name;
    }
  }
}

}  // namespace
}  // namespace fitcal
