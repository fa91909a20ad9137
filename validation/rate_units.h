#pragma once
// The likely-units check for every model: encoder rates logged in deg/s, rpm or rev/s and read
// as rad/s scale every wheel's travel by the same factor, which no calibration inside the bounds
// can undo - and which the fit would otherwise absorb into absurd parameters or blame on the
// wiring. The nominal robot's odometry path length (translation + kTurnLengthM x rotation,
// replayed through the model's own kinematics) against the ground truth's, both measured between
// the same instants (the ground truth's samples: a ground truth of start and end poses only
// compares the straight line with the straight line), tells it: a ratio near 1 is rad/s; near
// 57.3 deg/s, 9.55 rpm, 0.159 rev/s.

#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/run_log.h"

namespace fitcal {

struct RateUnitsFinding {
  bool suspicious = false;
  double scale = 1.0;       // odometry path / ground-truth path, pooled over the runs
  std::string likely_unit;  // "deg/s", "rpm", "rev/s" or ""
  std::string message;      // one line when suspicious
};

// Ratios within [1 / kMaxPlausibleScale, kMaxPlausibleScale] are accepted: the bounds of any
// robot file allow far less than that, and the units above are far outside.
inline constexpr double kMaxPlausibleScale = 3.0;

RateUnitsFinding CheckModelRateUnits(const RobotModelInterface& model,
                                     const std::vector<RunLog>& runs);

}  // namespace fitcal
