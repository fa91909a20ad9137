#include "sim/model_scenarios.h"

#include <algorithm>
#include <functional>
#include <stdexcept>

#include "io/command_failure.h"
#include "io/text_file.h"
#include "models/model_registry.h"

namespace fitcal::sim {

namespace {

// The registered models (sorted by name) whose extras pass `has`, comma-separated.
std::string ModelNamesWith(const std::function<bool(const ModelExtras&)>& has) {
  std::vector<std::string> names;
  for (const ModelRegistration& m : RegisteredModels()) {
    if (has(m.extras)) names.push_back(m.name);
  }
  std::sort(names.begin(), names.end());
  return io::Joined(names, ", ");
}

// The stepped physics' own settings (ScenarioNoise: slip, injected effects), refused for a
// scenario without it: perfect tracking has no slip and no substep the effects act on.
void SetSteppedPhysics(const Robot& robot, const SimulationScenario& scenario,
                       const ScenarioNoise& noise, SimulationOptions* o) {
  if (scenario.stepped_physics && noise.wheel_relative_sigma) {
    throw UsageError("--wheel-slip-sigma acts on perfect tracking; the stepped physics of "
                     "--model " + robot.model + " slips as --slip-sigma says (docs/simulate.md)");
  }
  if (!scenario.stepped_physics) {
    if (noise.slip_sigma || !noise.injected_effects.empty()) {
      throw UsageError(std::string(noise.slip_sigma ? "--slip-sigma" : "--inject") +
                       " acts on the stepped physics of " +
                       ModelNamesWith([](const ModelExtras& e) {
                         return e.scenario.stepped_physics;
                       }) + ", not on --model " + robot.model + " (docs/simulate.md)");
    }
    return;
  }
  for (const effects::EffectValue& e : noise.injected_effects) {
    if (!robot.CanShow(e.id)) {
      throw UsageError(std::string("--inject ") + effects::Info(e.id).name + ": the " +
                       robot.model + " robot has no channel it acts on (it needs " +
                       (effects::NeedsWheelPair(e.id) ? "a pair of wheels" : "a steering angle") +
                       ")");
    }
  }
  o->rest_after_s = 1.5;  // the controller's lag settles before the run ends
  o->stepped.emplace();
  o->stepped->commanded_parameters = robot.nominal;
  if (noise.slip_sigma) o->stepped->slip_sigma = *noise.slip_sigma;
  o->stepped->injected_effects = noise.injected_effects;
}

// The model's recorder with the values `simulate` was given in place of its own.
ScenarioRecorder WithReplacements(ScenarioRecorder r, const ScenarioNoise& noise) {
  r.ticks_per_rev = noise.ticks_per_rev.value_or(r.ticks_per_rev);
  r.wheel_rate_sigma_rad_s = noise.wheel_rate_sigma_rad_s.value_or(r.wheel_rate_sigma_rad_s);
  r.wheel_relative_sigma = noise.wheel_relative_sigma.value_or(r.wheel_relative_sigma);
  r.angle_sigma_rad = noise.angle_sigma_rad.value_or(r.angle_sigma_rad);
  r.gt_position_sigma_m = noise.gt_position_sigma_m.value_or(r.gt_position_sigma_m);
  r.gt_heading_sigma_rad = noise.gt_heading_sigma_rad.value_or(r.gt_heading_sigma_rad);
  return r;
}

}  // namespace

SimulationOptions RecordedAs(const RobotModelInterface& model, const ScenarioRecorder& recorder,
                             std::uint64_t seed) {
  const Robot& robot = model.robot();
  SimulationOptions o;
  o.encoder_period_s = recorder.encoder_period_s;
  o.ground_truth_period_s = recorder.ground_truth_period_s;
  if (recorder.substep_s > 0.0) o.substep_s = recorder.substep_s;
  o.ticks_per_rev.assign(robot.channels.size(), 0.0);
  for (std::size_t i = 0; i < robot.channels.size(); ++i) {
    if (robot.channels[i].kind == ChannelKind::kWheelRate) {
      o.ticks_per_rev[i] = recorder.ticks_per_rev;
    }
  }
  o.wheel_rate_sigma_rad_s = recorder.wheel_rate_sigma_rad_s;
  o.wheel_relative_sigma = recorder.wheel_relative_sigma;
  o.angle_sigma_rad = recorder.angle_sigma_rad;
  o.gt_position_sigma_m = recorder.gt_position_sigma_m;
  o.gt_heading_sigma_rad = recorder.gt_heading_sigma_rad;
  o.start_position_range_m = recorder.start_position_range_m;
  o.random_start_heading = recorder.random_start_heading;
  o.seed = seed;
  o.dynamics = ExtrasOf(robot.model).scenario.dynamics;
  return o;
}

std::string ScenarioModelNames() {
  return ModelNamesWith([](const ModelExtras& e) { return bool(e.scenario.trajectories); });
}

ModelScenario MakeModelScenario(const RobotModelInterface& model, const std::vector<double>& truth,
                                const ScenarioNoise& noise) {
  const Robot& robot = model.robot();
  const SimulationScenario& scenario = ExtrasOf(robot.model).scenario;
  if (!scenario.trajectories) {
    throw std::invalid_argument(
        "no calibration trajectories for model '" + robot.model + "' (simulate --model takes " +
        ScenarioModelNames() + ")");
  }
  ModelScenario out;
  out.repetitions = noise.repetitions.value_or(scenario.default_repetitions);
  out.repetition_unit = scenario.repetition_unit;
  if (out.repetitions < 0) throw std::invalid_argument("--repetitions must be at least 0");
  // Every run is simulated in memory before the data set is written: 2e9 repetitions grew by
  // 140 MB/s until the machine ran out. A thousand of each path is more than any calibration uses.
  constexpr int kMostRepetitions = 1000;
  if (out.repetitions > kMostRepetitions) {
    throw UsageError("--repetitions " + std::to_string(out.repetitions) + ": at most " +
                     std::to_string(kMostRepetitions) + " (every run is held in memory)");
  }
  out.trajectories = scenario.trajectories(model, truth, out.repetitions);
  if (out.trajectories.empty()) {
    throw UsageError("--repetitions 0: the " + robot.model +
                     " scenario drives no run without repetitions");
  }
  out.options = RecordedAs(model, WithReplacements(scenario.recorder, noise), noise.seed);
  SetSteppedPhysics(robot, scenario, noise, &out.options);
  if (scenario.stepped_physics) out.digits = EncoderCsvDigits::kRecorder;
  return out;
}

SimulateFn ScenarioSimulator(const RobotModelInterface& model, const ScenarioRecorder& recorder) {
  return [&model, recorder](const std::vector<double>& truth,
                            const std::vector<TrajectorySpec>& specs, std::uint64_t seed) {
    std::vector<RunLog> logs;
    const SimulationOptions options = RecordedAs(model, recorder, seed);
    for (ModelSimulatedRun& run : SimulateRuns(model, truth, specs, options)) {
      logs.push_back(std::move(run.log));
    }
    return logs;
  };
}

std::string ReproducePaperTables(const std::string& model, const PaperTablesRequest& request) {
  const ModelRegistration* registration = FindModel(model);
  if (registration == nullptr || !registration->extras.paper_tables.reproduce) {
    throw UsageError("--model " + model + " reproduces no paper's tables (models that do: " +
                     ModelNamesWith([](const ModelExtras& e) {
                       return bool(e.paper_tables.reproduce);
                     }) + ")");
  }
  const PaperTables& tables = registration->extras.paper_tables;
  const RobotModelPtr nominal =
      ReadRobotModel(YAML::Load(registration->example_yaml), model + " example robot");
  ScenarioRecorder recorder = tables.recorder;
  recorder.wheel_relative_sigma = request.wheel_slip_sigma;
  return tables.reproduce(*nominal, request, ScenarioSimulator(*nominal, recorder));
}

std::vector<double> DefaultTrueParameters(const Robot& robot, std::uint64_t seed) {
  const SimulationScenario& scenario = ExtrasOf(robot.model).scenario;
  if (scenario.default_truth) return scenario.default_truth(robot, seed);
  const double fraction = scenario.truth_fraction;
  std::vector<double> p = robot.nominal;
  int moved = 0;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (robot.IsHeld(k)) continue;
    const double bound = moved % 2 == 0 ? robot.bounds[k].hi : robot.bounds[k].lo;
    p[k] += fraction * (bound - robot.nominal[k]);
    ++moved;
  }
  return p;
}

}  // namespace fitcal::sim
