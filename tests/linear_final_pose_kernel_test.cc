// The final-pose kernel (odometry/linear_final_pose_kernel.h) against the replay it replaces in
// the NLopt objective (fit/model_nlopt_fit.h), for every registered model whose body step is
// linear in its channels (RobotModelInterface::StepMatrix: omni3, omni): the same final pose to
// rounding in every series tier, for run lengths that do not fill a block, on the simulated flower
// over the Eq. 16 box, and a swap of two channels seen as the replay sees it.

#include "odometry/linear_final_pose_kernel.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <random>

#include "models/model_registry.h"
#include "models/omni3/omni3_robot_model.h"
#include "tests/flower_scenario.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace {

// Rates (rad/s) around a common spin `spin_rad_s` of the wheels, which turns an omni robot at
// roughly r/R * spin: the spin sets how far the heading moves inside a block, hence the tier.
EncoderSamples SpinningLog(int channels, std::size_t n, double spin_rad_s, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> rate(-3.0, 3.0), dt(0.005, 0.015);
  EncoderSamples samples(channels);
  samples.resize(n);
  for (auto&& s : samples) {
    s.dt_s = dt(rng);
    for (int i = 0; i < channels; ++i) s.value[i] = spin_rad_s + rate(rng);
  }
  return samples;
}

// The replay's path length (m), the scale of the position's rounding.
double PathLength(const RobotModelInterface& model, const double* p, const EncoderSamples& log) {
  double length = 0.0;
  Pose2d previous;
  model.Replay(p, log, 0, log.size(), Pose2d{}, [&](std::size_t, const Pose2d& pose) {
    length += std::hypot(pose.x - previous.x, pose.y - previous.y);
    previous = pose;
  });
  return length;
}

// Both sum the same terms in different orders: a few ulps per sample of the path.
void ExpectSamePose(const Pose2d& kernel, const Pose2d& replay, double path_m) {
  const double tol_m = 1e-13 * (1.0 + path_m);
  EXPECT_NEAR(kernel.x, replay.x, tol_m);
  EXPECT_NEAR(kernel.y, replay.y, tol_m);
  EXPECT_NEAR(kernel.theta, replay.theta, 1e-12 * (1.0 + std::abs(replay.theta)));
}

std::vector<double> StepMatrixOf(const RobotModelInterface& model, const double* p) {
  std::vector<double> m(3 * static_cast<std::size_t>(model.robot().NumChannels()));
  EXPECT_TRUE(model.StepMatrix(p, m.data()));
  return m;
}

TEST(LinearFinalPoseKernel, EqualsTheReplayInEverySeriesTierForEveryLinearModel) {
  int linear_models = 0;
  for (const ModelRegistration& registration : RegisteredModels()) {
    const RobotModelPtr model = ReadRobotModel(YAML::Load(registration.example_yaml), "robot.yaml");
    const Robot& robot = model->robot();
    std::vector<double> m(3 * static_cast<std::size_t>(robot.NumChannels()));
    if (!model->StepMatrix(robot.nominal.data(), m.data())) continue;
    ++linear_models;
    const Pose2d start{0.4, -1.2, 2.9};
    // Spins from none (short series) to several turns per second (library sin/cos).
    for (double spin : {0.0, 2.0, 5.0, 10.0, 40.0, 150.0}) {
      for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{63}, std::size_t{64},
                            std::size_t{65}, std::size_t{1000}}) {
        SCOPED_TRACE(registration.name + ", spin " + std::to_string(spin) + " rad/s, " +
                     std::to_string(n) + " samples");
        const EncoderSamples log =
            SpinningLog(robot.NumChannels(), n, spin, static_cast<unsigned>(n + 7));
        const Pose2d replay = model->Replay(robot.nominal.data(), log, 0, log.size(), start);
        const Pose2d kernel = LinearFinalPoseKernel(log).FinalPose(m.data(), start);
        ExpectSamePose(kernel, replay, PathLength(*model, robot.nominal.data(), log));
      }
    }
  }
  EXPECT_GE(linear_models, 2) << "omni3 and omni declare kLinearInChannels";
}

// Six wheels take the loops over a run-time channel count (3 and 4 have fused ones).
TEST(LinearFinalPoseKernel, EqualsTheReplayForSixChannels) {
  const RobotModelPtr model = ReadRobotModel(YAML::Load(R"(model: omni
name: six_mecanum
wheels:
  - {name: fl, distance_m: 0.25, angle_deg: 36.86989765, radius_m: 0.05, drive_angle_deg: 0, roller_angle_deg: -45}
  - {name: fr, distance_m: 0.25, angle_deg: -36.86989765, radius_m: 0.05, drive_angle_deg: 0, roller_angle_deg: 45}
  - {name: ml, distance_m: 0.15, angle_deg: 90, radius_m: 0.05, drive_angle_deg: 0, roller_angle_deg: 45}
  - {name: mr, distance_m: 0.15, angle_deg: -90, radius_m: 0.05, drive_angle_deg: 0, roller_angle_deg: -45}
  - {name: rl, distance_m: 0.25, angle_deg: 143.13010235, radius_m: 0.05, drive_angle_deg: 0, roller_angle_deg: 45}
  - {name: rr, distance_m: 0.25, angle_deg: -143.13010235, radius_m: 0.05, drive_angle_deg: 0, roller_angle_deg: -45}
bounds:
  distance_m: [0.12, 0.28]
  radius_m: [0.045, 0.055]
  angle_offset_deg: [-2.0, 2.0]
)"),
                                                "six.yaml");
  const Robot& robot = model->robot();
  ASSERT_EQ(robot.NumChannels(), 6);
  const std::vector<double> m = StepMatrixOf(*model, robot.nominal.data());
  for (double spin : {0.0, 5.0, 150.0}) {
    SCOPED_TRACE("spin " + std::to_string(spin));
    const EncoderSamples log = SpinningLog(6, 1000, spin, 5);
    const Pose2d start{0.4, -1.2, 2.9};
    ExpectSamePose(LinearFinalPoseKernel(log).FinalPose(m.data(), start),
                   model->Replay(robot.nominal.data(), log, 0, log.size(), start),
                   PathLength(*model, robot.nominal.data(), log));
  }
}

TEST(LinearFinalPoseKernel, EqualsTheReplayOnFlowerRunsOverTheParameterBox) {
  sim::FlowerSimulation options = sim::PalacinFlower();
  options.repetitions = 1;
  const std::vector<sim::ModelSimulatedRun> runs = sim::SimulateFlower(options);
  const Omni3Model& model = DefaultOmni3Model();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> distance(0.170, 0.220), radius(0.138, 0.158),
      angle(-0.035, 0.035);
  for (int draw = 0; draw < 5; ++draw) {
    const auto table5 = sim::PalacinTable5Parameters().ToArray();
    std::vector<double> p(table5.begin(), table5.end());
    for (int i = 0; i < 3; ++i) {
      p[i] = distance(rng);  // Eq. 15 order: R_a..R_c, r_a..r_c, delta_a..delta_c
      p[3 + i] = radius(rng);
      p[6 + i] += angle(rng);
    }
    const std::vector<double> m = StepMatrixOf(model, p.data());
    for (const sim::ModelSimulatedRun& run : runs) {
      const EncoderSamples& log = run.log.encoders.samples;
      const Pose2d start{0.0, 0.0, 0.3};
      ExpectSamePose(LinearFinalPoseKernel(log).FinalPose(m.data(), start),
                     model.Replay(p.data(), log, 0, log.size(), start),
                     PathLength(model, p.data(), log));
    }
  }
}

TEST(LinearFinalPoseKernel, SeesAWheelSwap) {
  // Not a symmetric function of the wheels: swapping two columns of the data moves the pose as
  // much as in the replay (guards against summing the wrong step with the wrong offset).
  const Omni3Model& model = DefaultOmni3Model();
  const auto table5 = sim::PalacinTable5Parameters().ToArray();
  const std::vector<double> p(table5.begin(), table5.end());
  const std::vector<double> m = StepMatrixOf(model, p.data());
  const EncoderSamples log = SpinningLog(3, 500, 5.0, 11);
  EncoderSamples swapped = log;
  for (auto&& s : swapped) std::swap(s.value[0], s.value[1]);
  const Pose2d a = LinearFinalPoseKernel(log).FinalPose(m.data(), Pose2d{});
  const Pose2d b = LinearFinalPoseKernel(swapped).FinalPose(m.data(), Pose2d{});
  EXPECT_GT(std::hypot(a.x - b.x, a.y - b.y), 0.01);
  ExpectSamePose(b, model.Replay(p.data(), swapped, 0, swapped.size(), Pose2d{}),
                 PathLength(model, p.data(), swapped));
}

TEST(LinearFinalPoseKernel, ModelsNotLinearInTheirChannelsSaySo) {
  // The tricycle's steering angle enters its step through cos and sin: no step matrix.
  for (const ModelRegistration& registration : RegisteredModels()) {
    if (registration.name != "tricycle") continue;
    const RobotModelPtr model = ReadRobotModel(YAML::Load(registration.example_yaml), "robot.yaml");
    std::vector<double> m(3 * static_cast<std::size_t>(model->robot().NumChannels()));
    EXPECT_FALSE(model->StepMatrix(model->robot().nominal.data(), m.data()));
  }
}

}  // namespace
}  // namespace fitcal
