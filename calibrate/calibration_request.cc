#include "calibrate/calibration_request.h"

#include <set>

namespace fitcal {

std::string TrainingSelection(const CalibrationRequest& request) {
  if (!request.training_ids.empty()) return "the split's training runs";
  if (!request.train_trajectories.empty()) {
    return "trajectories matching '" + request.train_trajectories + "'";
  }
  return "repetitions " + request.train_reps;
}

RunSplit SplitOfRequest(const CalibrationRequest& request) {
  if (request.training_ids.empty()) {
    return SplitForFit(AlignRuns(request.runs), request.train_reps, request.train_trajectories);
  }
  const std::set<std::string> training(request.training_ids.begin(), request.training_ids.end());
  return SplitWhere(AlignRuns(request.runs),
                    [&](const AlignedRun& run) { return training.count(run.id) > 0; });
}

}  // namespace fitcal
