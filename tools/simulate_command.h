#pragma once
// `fitcal simulate`: writes a simulated flower data set (README.md, section Simulator) in the data
// set format.

#include <string>
#include <vector>

#include "tools/sim/omni3_simulator.h"

namespace fitcal::tools {

struct SimulateCommandOptions {
  std::string out;
  std::string robot = "data/robots/apr02.yaml";  // nominal robot: commands + fit start
  std::string truth;                             // robot YAML of the true robot; "" = Table 5
  bool force = false;
  // Effects to inject, "name=v1[,v2]" with the registry's names and parameter order
  // (odometry/effects.h); the data set written names none of them.
  std::vector<std::string> inject;
  sim::Omni3SimulationOptions sim;
};

int RunSimulateCommand(const SimulateCommandOptions& options);

}  // namespace fitcal::tools
