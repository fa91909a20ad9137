#pragma once
// `fitcal simulate`: writes a simulated flower data set (docs/simulator.md) in the data set format.

#include <string>

#include "tools/sim/omni3_simulator.h"

namespace fitcal::tools {

struct SimulateCommandOptions {
  std::string out;
  std::string robot = "data/robots/apr02.yaml";  // nominal robot: commands + fit start
  std::string truth;                              // robot YAML of the true robot; "" = Table 5
  bool force = false;
  sim::Omni3SimulationOptions sim;
};

int RunSimulateCommand(const SimulateCommandOptions& options);

}  // namespace fitcal::tools
