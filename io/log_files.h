#pragma once
// Loaders for the per-run log files of a data set (format: docs/data_format.md).

#include <string>

#include "odometry/run_log.h"

namespace fitcal::io {

// Encoder CSV, header `t,w_a,w_b,w_c`: t in s (strictly increasing), w the mean wheel rate in
// rad/s over (t(k-1), t(k)]; row 0 only sets the start time.
EncoderLog ReadEncoderCsv(const std::string& path);

// Ground truth: CSV with header `t,x,y,theta` (s, m, m, rad), or a TUM trajectory
// (`t x y z qx qy qz qw`, blank-separated, '#' comments) whose yaw is taken from the quaternion.
GroundTruthTrack ReadGroundTruth(const std::string& path);

}  // namespace fitcal::io
