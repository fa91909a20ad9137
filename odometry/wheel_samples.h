#pragma once
// What the replay consumes: one entry per encoder interval (t(k-1), t(k)], holding the interval's
// length and the mean wheel rates over it. A flat array of these is the whole odometry input of a
// run; 32 bytes per sample, read front to back.

#include <cstddef>
#include <vector>

namespace fitcal {

struct WheelSample {
  double dt_s = 0.0;
  double rate_rad_s[3] = {0.0, 0.0, 0.0};
};

using WheelSamples = std::vector<WheelSample>;

}  // namespace fitcal
