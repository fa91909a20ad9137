#pragma once
// Palacin et al. 2022's flower for the tests and benchmarks: APR-02 (models/omni3) drives the 36
// trajectories of Table A1 commanded with its nominal parameters (Eq. 15) while it moves with the
// true ones (Table 5), under omni3's registered scenario (models/omni3/omni3_extras.h: the stepped
// physics of sim/model_scenarios.h, whose defaults wrote the shipped data/flower). A test changes
// any field (fewer trajectories, no slip, a hook) before SimulateFlower.

#include <utility>
#include <vector>

#include "models/omni/flower_trajectories.h"
#include "models/omni3/omni3_extras.h"
#include "models/omni3/omni3_robot_model.h"
#include "sim/model_scenarios.h"
#include "sim/model_simulator.h"
#include "tests/omni3_robot.h"

namespace fitcal::sim {

// A whole flower simulation: the nominal robot (it commands; fits start from it), the truth,
// the commands, the repetitions and the options.
struct FlowerSimulation {
  RobotModelPtr model;
  std::vector<double> true_parameters;
  std::vector<MotionCommand> trajectories = FlowerTrajectories();
  int repetitions = 10;
  SimulationOptions options;
};

// APR-02 (Eq. 15 nominal) with the Table 5 truth and the scenario's default noise.
inline FlowerSimulation PalacinFlower() {
  FlowerSimulation f;
  f.model = Omni3ModelOf(PalacinApr02Robot());
  f.true_parameters = ParameterVector(PalacinTable5Parameters());
  f.options = MakeModelScenario(*f.model, f.true_parameters, ScenarioNoise{}).options;
  return f;
}

// The same without noise: no slip, no ground-truth noise, no jitter and near-ideal encoders
// (2^22 counts/rev), one repetition. What then remains between the simulator and Eq. 4 is the
// replay's discretisation.
inline FlowerSimulation NoiseFreePalacinFlower() {
  FlowerSimulation f = PalacinFlower();
  f.repetitions = 1;
  f.options.gt_position_sigma_m = 0.0;
  f.options.gt_heading_sigma_rad = 0.0;
  f.options.ticks_per_rev.assign(omni3::kNumWheels, static_cast<double>(1 << 22));
  f.options.stepped->slip_sigma = 0.0;
  f.options.stepped->encoder_jitter_s = 0.0;
  return f;
}

// All trajectories x repetitions, ordered by repetition then trajectory; ids "<label>-rep<NN>".
inline std::vector<ModelSimulatedRun> SimulateFlower(const FlowerSimulation& flower) {
  return SimulateRuns(*flower.model, flower.true_parameters,
                      FlowerSpecs(flower.trajectories, flower.repetitions), flower.options);
}

// The same, only the logs (what most callers want).
inline std::vector<RunLog> SimulateFlowerLogs(const FlowerSimulation& flower) {
  std::vector<RunLog> logs;
  for (ModelSimulatedRun& run : SimulateFlower(flower)) logs.push_back(std::move(run.log));
  return logs;
}

}  // namespace fitcal::sim
