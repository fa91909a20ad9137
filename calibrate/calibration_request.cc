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

std::string AbsentRepetitionRefusal(const CalibrationRequest& request) {
  if (!request.training_ids.empty() || !request.train_trajectories.empty() ||
      request.train_reps == "auto") {
    return "";
  }
  std::set<int> present;
  for (const RunLog& run : request.runs) present.insert(run.repetition);
  for (const int named : RepetitionsNamedAlone(request.train_reps)) {
    if (present.count(named) == 0) {
      return "--train-reps names repetition " + std::to_string(named) + ", which no run of " +
             request.dataset + " has (repetitions " +
             FormatRepetitionList(std::vector<int>(present.begin(), present.end())) + ")";
    }
  }
  return "";
}

}  // namespace fitcal
