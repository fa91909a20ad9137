#pragma once
// `fitcal simulate`: writes a simulated calibration data set of the --model (default: the --robot's
// model; omni3's scenario is Palacin's flower) through sim/model_dataset.h (docs/simulate.md).

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "sim/model_simulator.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

// The noise flags replace the model's recorder's values (ModelExtras::scenario.recorder) only when
// given: each is read into the request from `given` (its flag names).
struct SimulateCommandOptions {
  std::string out;
  std::string model;  // "": the --robot's model
  std::string robot = "data/robots/apr02.yaml";  // nominal robot: commands + fit start
  std::string truth;  // robot YAML of the true robot; "" = the scenario's default
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
  double wheel_slip_sigma = 0.0;                          // perfect tracking only
  double wheel_rate_sigma_rad_s = 0.02;
  double angle_sigma_deg = 0.1;
  std::set<std::string> given;  // the flags given, e.g. "--robot"
};

// Declares every flag of `simulate` on its subcommand `app`, bound to `options`; once parsed, the
// flags given are recorded.
void AddSimulateOptions(CLI::App& app, SimulateCommandOptions& options);

int RunSimulateCommand(const SimulateCommandOptions& options);

}  // namespace fitcal::tools
