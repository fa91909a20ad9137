// Closing the loop on a model other than omni3 (diagnosis/diagnose.h through the seam): a tricycle
// whose steering sensor reads a scaled angle. The diagnosis must name steering_scale with its
// size and improve the held-out error; on the clean tricycle it must accept nothing.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>
#include <vector>

#include "diagnosis/diagnose.h"
#include "fit/effect_fit.h"
#include "fit/run_split.h"
#include "models/tricycle/tricycle_model.h"
#include "tests/diagnose_expectations.h"
#include "sim/model_simulator.h"
#include "models/tricycle/tricycle_trajectories.h"

namespace fitcal {
namespace {

struct Split {
  std::vector<TrackRun> training, validation;
};

// The example tricycle (truth = nominal with the wheelbase and offset moved), circles at four
// steering angles both ways and squares, three repetitions: the first trains, the others
// validate (20 held-out runs: the paired t test of diagnose needs them, since a scale error shows
// most on the sharpest circles and little on the others). The recorded steering angle is the true
// one divided by (1 + steering_scale).
Split Simulate(const RobotModelInterface& model, double steering_scale, std::uint64_t seed) {
  std::vector<double> truth = model.robot().nominal;
  truth[1] *= 1.02;
  truth[2] += 0.5 * M_PI / 180.0;
  sim::TricycleTrajectoryOptions trajectories;
  trajectories.repetitions = 3;
  sim::SimulationOptions options;
  options.encoder_period_s = 0.02;
  options.ground_truth_period_s = 0.05;
  options.wheel_rate_sigma_rad_s = 0.02;
  options.angle_sigma_rad = 0.002;
  options.gt_position_sigma_m = 0.002;
  options.gt_heading_sigma_rad = 0.004;
  options.record_start_pose = true;
  options.seed = seed;
  std::vector<RunLog> logs;
  for (auto& s :
       sim::SimulateRuns(model, truth, sim::TricycleTrajectories(trajectories), options)) {
    RunLog log = s.log;
    EncoderSamples scaled(log.encoders.samples.num_channels());
    for (const auto& sample : log.encoders.samples) {
      const double values[2] = {sample.value[0], sample.value[1] / (1.0 + steering_scale)};
      scaled.push_back(sample.dt_s, values);
    }
    log.encoders.samples = scaled;
    logs.push_back(log);
  }
  SplitOf<TrackRun> split =
      SplitByRepetition(PrepareTrackRuns(logs, WheelChannelMask(model.robot())), {1});
  return {std::move(split.training), std::move(split.validation)};
}

std::shared_ptr<const RobotModelInterface> Tricycle() {
  return ReadTricycleModel(YAML::Load(kTricycleExampleYaml), "example");
}

TEST(TricycleDiagnose, NamesAScaledSteeringSensorWithItsSize) {
  const auto model = Tricycle();
  const double injected = effects::Info(effects::EffectId::kSteeringScale).typical[0];
  const Split d = Simulate(*model, injected, 21);
  fitcal::testing::ExpectDiagnoseNamesTheInjectedEffect(
      d.training, d.validation, *model, effects::EffectId::kSteeringScale, injected);
}

TEST(TricycleDiagnose, CleanTricycleAcceptsNothing) {
  const auto model = Tricycle();
  const Split d = Simulate(*model, 0.0, 22);
  fitcal::testing::ExpectDiagnoseAcceptsNothing(d.training, d.validation, *model);
}

}  // namespace
}  // namespace fitcal
