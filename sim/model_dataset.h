#pragma once
// The data set `fitcal simulate` writes (cli/simulate_command.cc reads the flags, calls this and
// prints): a simulated calibration data set of any model with a scenario (sim/model_scenarios.h;
// omni3's is Palacin's flower): the nominal robot (--robot, or the model's registry example)
// commands the trajectories, a true robot (--truth, or the scenario's default) drives them, and the
// data set - robot.yaml (nominal), true_robot.yaml (the truth, for checking a fit), dataset.yaml
// and the runs - is built in a temporary sibling directory and renamed into place
// (io/staged_directory.h).

#include <cstddef>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "sim/scenario_noise.h"

namespace fitcal::sim {

struct ModelDatasetRequest {
  std::string out;
  std::string model;  // "" = the robot's model
  std::string robot;  // "" = the model's registry example robot
  std::string truth;  // "" = the default true robot (model_scenarios.h)
  bool force = false;
  ScenarioNoise noise;
};

struct WrittenModelDataset {
  RobotModelPtr model;         // the nominal robot, as robot.yaml holds it
  std::vector<double> truth;   // the true parameters, as true_robot.yaml holds them
  std::size_t num_runs = 0;
  int repetitions = 0;         // as asked, or the scenario's default
  std::string repetition_unit;  // the scenario's: "repetitions", asoc's "excursions"
};

// Throws UsageError for an `out` it may not write or a robot of another model,
// std::invalid_argument for an unknown model or a truth that does not fit the robot; nothing is
// written then.
WrittenModelDataset WriteModelDataset(const ModelDatasetRequest& request);

}  // namespace fitcal::sim
