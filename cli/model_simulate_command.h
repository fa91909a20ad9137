#pragma once
// `fitcal simulate --model <name>`: a simulated calibration data set of any model with
// calibration trajectories (sim/model_scenarios.h): the nominal robot (--robot, or the
// model's registry example) commands the trajectories, a true robot (--truth, or the nominal moved
// part of the way to its bounds) drives them, and the data set - robot.yaml (nominal),
// true_robot.yaml (the truth, for checking a fit), dataset.yaml and the runs - is built in a
// temporary sibling directory and renamed into place (io/staged_directory.h).

#include <string>
#include <vector>

#include "sim/scenario_noise.h"

namespace fitcal::tools {

struct ModelSimulateOptions {
  std::string out;
  std::string model;
  std::string robot;  // "" = the model's registry example robot
  std::string truth;  // "" = the default true robot (model_scenarios.h)
  bool force = false;
  sim::ScenarioNoise noise;
  std::vector<std::string> flower_only_flags;  // given flags that only the flower simulation takes
};

// Exit codes: 0 written; 1 bad input (one line); 2 usage (an existing --out without --force, a
// flag only the flower simulation takes, a robot of another model).
int RunModelSimulateCommand(const ModelSimulateOptions& options);

}  // namespace fitcal::tools
