#include "fit/run_split.h"

#include <algorithm>
#include <set>
#include <stdexcept>

#include "fit/trajectory_split.h"

namespace fitcal {

namespace {
int ParseInt(const std::string& s, const std::string& whole) {
  if (s.empty() || s.size() > 6 || s.find_first_not_of("0123456789") != std::string::npos) {
    throw std::invalid_argument("repetition list '" + whole + "': '" + s +
                                "' is not a whole number");
  }
  return std::stoi(s);
}
}  // namespace

std::vector<int> ParseRepetitionList(const std::string& text) {
  std::set<int> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t end = text.find(',', pos);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(pos, end - pos);
    const std::size_t dash = item.find('-');
    if (dash == std::string::npos) {
      out.insert(ParseInt(item, text));
    } else {
      const int lo = ParseInt(item.substr(0, dash), text);
      const int hi = ParseInt(item.substr(dash + 1), text);
      if (lo > hi)
        throw std::invalid_argument("repetition list '" + text + "': range " + item +
                                    " is reversed");
      for (int r = lo; r <= hi; ++r) out.insert(r);
    }
    pos = end + 1;
  }
  return {out.begin(), out.end()};
}

std::string FormatRepetitionList(const std::vector<int>& reps) {
  std::string out;
  for (std::size_t i = 0; i < reps.size();) {
    std::size_t j = i;
    while (j + 1 < reps.size() && reps[j + 1] == reps[j] + 1) ++j;
    if (!out.empty()) out += ",";
    out += std::to_string(reps[i]);
    if (j > i) out += "-" + std::to_string(reps[j]);
    i = j + 1;
  }
  return out.empty() ? "none" : out;
}

RunSplit SplitByRepetition(std::vector<AlignedRun> runs, const std::vector<int>& training_reps) {
  RunSplit split;
  std::set<int> train_set(training_reps.begin(), training_reps.end());
  std::set<int> seen_train, seen_validation;
  for (AlignedRun& run : runs) {
    if (train_set.count(run.repetition)) {
      seen_train.insert(run.repetition);
      split.training.push_back(std::move(run));
    } else {
      seen_validation.insert(run.repetition);
      split.validation.push_back(std::move(run));
    }
  }
  split.training_repetitions.assign(seen_train.begin(), seen_train.end());
  split.validation_repetitions.assign(seen_validation.begin(), seen_validation.end());
  return split;
}

RunSplit SplitByTrajectory(std::vector<AlignedRun> runs, const std::string& selector_text) {
  std::vector<std::string> labels;
  for (const AlignedRun& run : runs) labels.push_back(run.trajectory);
  const TrajectorySelector selector(selector_text, labels);
  RunSplit split;
  std::set<int> seen_train, seen_validation;
  for (AlignedRun& run : runs) {
    const bool trains = selector.Matches(run.trajectory);
    (trains ? seen_train : seen_validation).insert(run.repetition);
    (trains ? split.training : split.validation).push_back(std::move(run));
  }
  split.training_repetitions.assign(seen_train.begin(), seen_train.end());
  split.validation_repetitions.assign(seen_validation.begin(), seen_validation.end());
  return split;
}

RunSplit SplitForFit(std::vector<AlignedRun> runs, const std::string& train_reps,
                     const std::string& train_trajectories) {
  if (!train_trajectories.empty()) return SplitByTrajectory(std::move(runs), train_trajectories);
  return SplitByRepetition(std::move(runs), ParseRepetitionList(train_reps));
}

}  // namespace fitcal
