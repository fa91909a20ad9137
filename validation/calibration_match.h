#pragma once
// A calibration applied to runs recorded for another robot YAML of the same model: its values are
// applied by position (channel k of the logs drives channel k of the model, parameter k is
// parameter k), so the two must list the same channels and parameters in the same order.

#include <string>

#include "odometry/robot.h"

namespace fitcal {

// "" when `calibrated` lists what `dataset` lists in the same order (or other names altogether,
// another robot of the model: applied by position as it says); otherwise why not, naming both
// orders. A calibration with its wheels listed left before right, judged on a data set whose
// robot lists right first, swapped the wheels: a report's CF 0.030 read 0.121 and an export
// replayed the nominal at 10x its error.
std::string ChannelOrderRefusal(const Robot& calibrated, const Robot& dataset);

}  // namespace fitcal
