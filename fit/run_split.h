#pragma once
// Training / validation split (Palacin Sec. 3: repetitions 1-5 fit, 6-10 validate), by repetition
// or by trajectory label (fit/trajectory_split.h): the one split every command makes, of aligned
// runs (AlignedRun) and of runs prepared for track residuals (TrackRun, fit/effect_fit.h) alike.
// A run type joins by an AlignedOf(run) overload found beside it (argument-dependent lookup).

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "fit/trajectory_split.h"
#include "odometry/aligned_run.h"

namespace fitcal {

// Parses "1-5", "1,3,5" or "1-3,7": sorted, unique; throws std::invalid_argument otherwise.
std::vector<int> ParseRepetitionList(const std::string& text);
// The repetitions `text` names on their own, not in a range ("1,11,3-5": 1 and 11).
std::vector<int> RepetitionsNamedAlone(const std::string& text);
// "1-5" style text of a sorted list.
std::string FormatRepetitionList(const std::vector<int>& repetitions);
// "auto": the first half of the repetitions present (rounded up), how `diagnose` and `generalise`
// split by default; any other text as ParseRepetitionList.
std::vector<int> ResolveRepetitionList(const std::string& text, const std::set<int>& present);

inline const AlignedRun& AlignedOf(const AlignedRun& run) { return run; }

template <typename Run>
struct SplitOf {
  std::vector<Run> training;
  std::vector<Run> validation;
  std::vector<int> training_repetitions;    // present in the data
  std::vector<int> validation_repetitions;  // present in the data
};
using RunSplit = SplitOf<AlignedRun>;

// Each run, in order, to training where trains(AlignedOf(run)), else to validation.
template <typename Run, typename Trains>
SplitOf<Run> SplitWhere(std::vector<Run> runs, const Trains& trains) {
  SplitOf<Run> split;
  std::set<int> seen_train, seen_validation;
  for (Run& run : runs) {
    const bool train = trains(AlignedOf(run));
    (train ? seen_train : seen_validation).insert(AlignedOf(run).repetition);
    (train ? split.training : split.validation).push_back(std::move(run));
  }
  split.training_repetitions.assign(seen_train.begin(), seen_train.end());
  split.validation_repetitions.assign(seen_validation.begin(), seen_validation.end());
  return split;
}

template <typename Run>
SplitOf<Run> SplitByRepetition(std::vector<Run> runs, const std::vector<int>& training_reps) {
  const std::set<int> train(training_reps.begin(), training_reps.end());
  return SplitWhere(std::move(runs),
                    [&](const AlignedRun& run) { return train.count(run.repetition) > 0; });
}

// By trajectory label instead: the runs whose label the selector matches train (a list of labels
// or a regular expression, fit/trajectory_split.h); the repetition lists name what is
// present on each side. Throws std::invalid_argument for an invalid selector.
template <typename Run>
SplitOf<Run> SplitByTrajectory(std::vector<Run> runs, const std::string& selector_text) {
  std::vector<std::string> labels;
  for (const Run& run : runs) labels.push_back(AlignedOf(run).trajectory);
  const TrajectorySelector selector(selector_text, labels);
  return SplitWhere(std::move(runs),
                    [&](const AlignedRun& run) { return selector.Matches(run.trajectory); });
}

// SplitByTrajectory when `train_trajectories` is set, else SplitByRepetition of `train_reps`
// (ResolveRepetitionList): the choice `fitcal fit` and `diagnose` offer for every model.
template <typename Run>
SplitOf<Run> SplitForFit(std::vector<Run> runs, const std::string& train_reps,
                         const std::string& train_trajectories) {
  if (!train_trajectories.empty()) return SplitByTrajectory(std::move(runs), train_trajectories);
  std::set<int> present;
  for (const Run& run : runs) present.insert(AlignedOf(run).repetition);
  return SplitByRepetition(std::move(runs), ResolveRepetitionList(train_reps, present));
}

}  // namespace fitcal
