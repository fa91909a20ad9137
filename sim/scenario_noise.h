#pragma once
// What `simulate --model` is asked beyond the model's scenario: how many repetitions, the seed, and
// the recorder's values the user replaces (the model's own recorder, ModelExtras::scenario.recorder
// in models/model_extras.h, gives every value not set here; model_scenarios.h says why its
// defaults are what they are).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "models/model_extras.h"
#include "odometry/effects.h"

namespace fitcal::sim {

struct ScenarioNoise {
  std::optional<int> repetitions;  // unset: the scenario's default_repetitions
  std::uint64_t seed = 1;
  // The recorder's values given; unset: the model recorder's (ScenarioRecorder's fields).
  std::optional<double> ticks_per_rev;
  std::optional<double> wheel_rate_sigma_rad_s;
  std::optional<double> wheel_relative_sigma;  // perfect tracking only (refused elsewhere)
  std::optional<double> angle_sigma_rad;
  std::optional<double> gt_position_sigma_m;
  std::optional<double> gt_heading_sigma_rad;
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
