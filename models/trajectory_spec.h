#pragma once
// A calibration trajectory as the simulator drives it: body twists held for given durations
// (sim/model_simulator.h turns one into encoder and ground-truth logs). Here, below the
// simulator, so that a model can register the trajectories it is calibrated on
// (models/model_extras.h) without knowing the simulator.

#include <string>
#include <vector>

#include "models/model_interface.h"

namespace fitcal::sim {

struct TwistSegment {
  Twist twist;
  double duration_s = 0.0;
};

struct TrajectorySpec {
  std::string label;  // the data set's trajectory label; repetitions share it
  int repetition = 1;
  std::vector<TwistSegment> segments;
};

}  // namespace fitcal::sim
