#pragma once
// An omni3 robot in named fields: its nominal geometry (Palacin Eq. 15) and the box within which
// the fit may move each parameter (Eq. 16), as the paper-reproduction code and the OptiOdom
// importer hold it. Read with ReadOmni3Robot and put on the model seam with Omni3ModelOf
// (omni3_robot_model.h); every fit runs through the seam.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "models/omni3/omni3_parameters.h"
#include "odometry/effects.h"
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

  // Per-parameter [lo, hi] in the flat order of omni3_parameters.h.
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
