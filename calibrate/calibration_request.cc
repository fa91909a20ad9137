#include "calibrate/calibration_request.h"

#include <algorithm>
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
  const std::string& text = request.train_reps;
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    start = comma + 1;
    if (item.empty() || item.find('-') != std::string::npos) continue;
    const std::vector<int> named = ParseRepetitionList(item);
    if (named.size() == 1 && present.count(named[0]) == 0) {
      return "--train-reps names repetition " + item + ", which no run of " + request.dataset +
             " has (repetitions " +
             FormatRepetitionList(std::vector<int>(present.begin(), present.end())) + ")";
    }
  }
  return "";
}

}  // namespace fitcal
