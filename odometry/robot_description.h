#pragma once
// What fitcal knows about a robot before fitting: its nominal geometry (Palacin Eq. 15) and the
// box within which the fit may move each parameter (Eq. 16). Filled from the robot YAML by io/.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "odometry/effects.h"
#include "odometry/omni3_model.h"
#include "odometry/robot.h"

namespace fitcal {

struct Omni3Bounds {
  Interval distance_m;        // absolute bounds on every R_i
  Interval radius_m;          // absolute bounds on every r_i
  Interval angle_offset_rad;  // bounds on delta_i - nominal delta_i (Eq. 16)
};

struct Omni3Robot {
  std::string name;
  std::array<std::string, omni3::kNumWheels> wheel_names{"a", "b", "c"};
  omni3::Parameters nominal;
  Omni3Bounds bounds;
  std::optional<EncoderTicks> encoder;  // set when the encoder logs are in ticks
  // Effects beyond the nine parameters (robot YAML `effects:`, written by `fitcal diagnose`);
  // replayed by odometry/effects.h ReplayStepsWithEffects.
  std::vector<effects::EffectValue> effects;

  // Per-parameter [lo, hi] in the flat order of omni3_model.h.
  std::array<Interval, omni3::kNumParameters> ParameterBounds() const {
    std::array<Interval, omni3::kNumParameters> out{};
    for (int i = 0; i < omni3::kNumWheels; ++i) {
      out[omni3::kDistanceIndex + i] = bounds.distance_m;
      out[omni3::kRadiusIndex + i] = bounds.radius_m;
      out[omni3::kAngleIndex + i] = {nominal.angle_rad[i] + bounds.angle_offset_rad.lo,
                                     nominal.angle_rad[i] + bounds.angle_offset_rad.hi};
    }
    return out;
  }
};

}  // namespace fitcal
