#pragma once
// The noise settings of a simulated data set of a model on the seam (model_scenarios.h describes
// each and why these defaults), as `simulate --model` takes them.

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "odometry/effects.h"

namespace fitcal::sim {

struct ScenarioNoise {
  int repetitions = 10;
  std::uint64_t seed = 1;
  double encoder_period_s = 0.010;
  double ticks_per_rev = 4096.0;  // wheel channels; 0 = no quantisation
  double wheel_rate_sigma_rad_s = 0.02;
  double wheel_relative_sigma = 0.0;  // SimulationOptions::wheel_relative_sigma
  double angle_sigma_rad = 0.1 * M_PI / 180.0;
  double ground_truth_period_s = 0.2;
  double gt_position_sigma_m = 0.002;
  double gt_heading_sigma_rad = 0.2 * M_PI / 180.0;
  double start_position_range_m = 2.0;
  // The stepped physics only (ModelExtras::scenario.stepped_physics; refused elsewhere): the
  // wheel slip's sigma (unset: SteppedOptions' default) and library effects the data set does not
  // name.
  std::optional<double> slip_sigma;
  std::vector<effects::EffectValue> injected_effects;
};

// The registered models that have calibration trajectories (ModelExtras::scenario), sorted:
// "diff_drive, omni, tricycle".
std::string ScenarioModelNames();

}  // namespace fitcal::sim
