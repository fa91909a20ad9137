#pragma once
// The recorded data of one ASOC run (Doebbler Sec. III): cumulative wheel angles of the six
// wheels and the absolute pivot encoder angles of the three castors, sampled together, plus the
// ground truth. No file knowledge here (models/asoc/asoc_files.h fills these).

#include <optional>
#include <string>
#include <vector>

#include "models/asoc/asoc_model.h"
#include "odometry/run_log.h"

namespace fitcal::asoc {

// One encoder sample: wheel_rad[i][k] the cumulative angle of wheel k (0 = "a" = wheel 1,
// 1 = "b" = wheel 2) of castor i; pivot_rad[i] the pivot encoder reading gamma_i (any turn).
struct EncoderSample {
  double wheel_rad[kNumCastors][2] = {{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}};
  double pivot_rad[kNumCastors] = {0.0, 0.0, 0.0};
};

// Samples at strictly increasing times t_s (same length). Odometry works on consecutive pairs.
struct EncoderLog {
  std::vector<double> t_s;
  std::vector<EncoderSample> samples;
};

struct RunLog {
  std::string id;
  std::string trajectory;  // e.g. "umbmark_cw", "hold_1_ccw"
  int repetition = 0;
  EncoderLog encoders;
  GroundTruthTrack ground_truth;
  std::optional<Pose2d> start_pose;
};

}  // namespace fitcal::asoc
