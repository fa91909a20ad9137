#pragma once
// `fitcal simulate`: writes a simulated calibration data set of the --model (default: the --robot's
// model; omni3's scenario is Palacin's flower) through sim/model_dataset.h (docs/simulate.md).

#include <cstdint>
#include <string>
#include <vector>

#include "sim/model_simulator.h"
#include "sim/scenario_noise.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

struct SimulateCommandOptions {
  std::string out;
  std::string model;  // "": the --robot's model
  std::string robot = "data/robots/apr02.yaml";  // nominal robot: commands + fit start
  bool robot_given = false;  // --model: without --robot the model's registry example is nominal
  std::string truth;         // robot YAML of the true robot; "" = the scenario's default
  bool force = false;
  // Effects to inject, "name=v1[,v2]" with the registry's names and parameter order
  // (odometry/effects.h); the data set written names none of them.
  std::vector<std::string> inject;
  int repetitions = 10;
  std::uint64_t seed = 1;
  int encoder_counts_per_rev = 4096;
  double gt_position_sigma_m = 0.002;
  double gt_heading_sigma_deg = 0.2;
  double slip_sigma = sim::SteppedOptions{}.slip_sigma;  // the stepped physics only
  bool slip_sigma_given = false;
  double wheel_rate_sigma_rad_s = sim::ScenarioNoise{}.wheel_rate_sigma_rad_s;
  double angle_sigma_deg = sim::ScenarioNoise{}.angle_sigma_rad * 180.0 / M_PI;
};

// Declares every flag of `simulate` on its subcommand `app`, bound to `options`; once parsed, the
// flags given are recorded.
void AddSimulateOptions(CLI::App& app, SimulateCommandOptions& options);

int RunSimulateCommand(const SimulateCommandOptions& options);

}  // namespace fitcal::tools
