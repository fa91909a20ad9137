#pragma once
// Loaders for the per-run log files of a data set (format: README.md, "Data set format").

#include <optional>
#include <string>

#include "odometry/robot_description.h"
#include "odometry/run_log.h"

namespace fitcal::io {

// Encoder CSV, header `t,w_a,w_b,w_c`: t in s (strictly increasing), w the mean wheel rate in
// rad/s over (t(k-1), t(k)]; row 0 only sets the start time.
// Or header `t,ticks_a,ticks_b,ticks_c`: encoder ticks, which need `ticks` (the robot YAML's
// `encoder:` block). Increments: row k holds the ticks counted over (t(k-1), t(k)] and row 0's
// are ignored (counted before the start); cumulative: running totals, row 0 is the reference.
// Either way w_i(k) = 2 pi dticks_i(k) / (ticks_per_rev dt(k)).
EncoderLog ReadEncoderCsv(const std::string& path,
                          const std::optional<EncoderTicks>& ticks = std::nullopt);

// Ground truth: CSV with header `t,x,y,theta` (s, m, m, rad), or a TUM trajectory
// (`t x y z qx qy qz qw`, blank-separated, '#' comments) whose yaw is taken from the quaternion.
GroundTruthTrack ReadGroundTruth(const std::string& path);

}  // namespace fitcal::io
