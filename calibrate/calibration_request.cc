#include "calibrate/calibration_request.h"

namespace fitcal {

std::string TrainingSelection(const CalibrationRequest& request) {
  if (!request.train_trajectories.empty()) {
    return "trajectories matching '" + request.train_trajectories + "'";
  }
  return "repetitions " + request.train_reps;
}

}  // namespace fitcal
