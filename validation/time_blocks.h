#pragma once
// Held-out time blocks of a long run: a data set of free driving may hold a single run, and a
// calibration from it must still be judged on driving it was not fitted on. The run is cut at
// encoder sample boundaries into blocks of equal ground-truth path length; each block is a run of
// its own, started at the ground truth's pose at its first instant and ended at its last, so its
// final pose (Palacin Eq. 14) judges an open path that sees the scale as well as the heading.

#include <vector>

#include "odometry/aligned_run.h"

namespace fitcal {

// Blocks k = 1..num_blocks of `run`, cut on its ground-truth track (AlignedRun::track), which
// each block keeps: id "<id>-block<k>", the run's trajectory label, repetition k. Throws
// std::invalid_argument when num_blocks < 1, the run has fewer samples than blocks or no track.
std::vector<AlignedRun> CutIntoTimeBlocks(const AlignedRun& run, int num_blocks);

}  // namespace fitcal
