#pragma once
// Which runs a calibration trains on: the trajectory strategies of Palacin et al. 2022 Table 4
// (Sec. 3.2) and any explicit list of trajectory labels, crossed with a set of repetitions.
//
//   STA  R1, R5, R9                       forward and +-120 deg straight runs
//   STB  B2, B6, B10, G12, G4, G8         forward and +-120 deg curves, both turning directions
//   STC  R1 .. R12                        all straight runs
//   STD  B1 .. B12, G1 .. G12             all curves
//   STE  all 36 (R, G and B 1 .. 12)      the whole flower

#include <string>
#include <vector>

#include "odometry/aligned_run.h"

namespace fitcal {

struct TrajectoryStrategy {
  std::string name;                 // "STB", or the list as the user wrote it
  std::vector<std::string> labels;  // trajectory labels, in the paper's order
};

// STA .. STE in Table 4's order.
const std::vector<TrajectoryStrategy>& PalacinStrategies();

// "STA".."STE" (any case), or a comma-separated list of labels where "B1-B12" stands for
// B1, B2, ..., B12 (same prefix, increasing numbers). Throws std::invalid_argument with the
// offending item on anything else (empty items, reversed or mixed-prefix ranges, duplicates).
TrajectoryStrategy ParseStrategy(const std::string& text);

// Labels of the strategy that no run in `runs` carries (empty when all are present).
std::vector<std::string> MissingTrajectories(const std::vector<AlignedRun>& runs,
                                             const TrajectoryStrategy& strategy);

// The runs whose trajectory is in the strategy and whose repetition is in `repetitions`, in the
// order of `runs`.
std::vector<AlignedRun> SelectRuns(const std::vector<AlignedRun>& runs,
                                   const TrajectoryStrategy& strategy,
                                   const std::vector<int>& repetitions);

}  // namespace fitcal
