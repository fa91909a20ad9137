#pragma once
// Training / validation split by repetition (Palacin Sec. 3: repetitions 1-5 fit, 6-10 validate).

#include <string>
#include <vector>

#include "odometry/aligned_run.h"

namespace fitcal {

// Parses "1-5", "1,3,5" or "1-3,7": sorted, unique; throws std::invalid_argument otherwise.
std::vector<int> ParseRepetitionList(const std::string& text);
// "1-5" style text of a sorted list.
std::string FormatRepetitionList(const std::vector<int>& repetitions);

struct RunSplit {
  std::vector<AlignedRun> training;
  std::vector<AlignedRun> validation;
  std::vector<int> training_repetitions;    // present in the data
  std::vector<int> validation_repetitions;  // present in the data
};

RunSplit SplitByRepetition(std::vector<AlignedRun> runs, const std::vector<int>& training_reps);

// By trajectory label instead: the runs whose label the selector matches train (a list of labels
// or a regular expression, fit/trajectory_split.h); the repetition lists name what is
// present on each side. Throws std::invalid_argument for an invalid selector.
RunSplit SplitByTrajectory(std::vector<AlignedRun> runs, const std::string& selector);

// SplitByTrajectory when `train_trajectories` is set, else SplitByRepetition of `train_reps`:
// the choice `fitcal fit --train-reps / --train-trajectories` offers for every model.
RunSplit SplitForFit(std::vector<AlignedRun> runs, const std::string& train_reps,
                     const std::string& train_trajectories);

}  // namespace fitcal
