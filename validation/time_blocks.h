#pragma once
// Held-out time blocks of a long run: a data set of free driving may hold a single run, and a
// calibration from it must still be judged on driving it was not fitted on. The run is cut at
// encoder sample boundaries into blocks of equal ground-truth path length; each block is a run of
// its own, started at the ground truth's pose at its first instant and ended at its last, so its
// final pose (Palacin Eq. 14) judges an open path that sees the scale as well as the heading.
//
// Where a boundary falls matters: the encoders and the ground truth run on clocks aligned only at
// the run's ends (docs/optiodom.md; a lag of -0.35 s on the omni3 joystick run), so a block cut
// while the robot moves starts and ends on a ground-truth pose that is off by the motion over the
// lag, and its start heading error turns its whole path. A run starts and ends at rest; its
// blocks do not. Each boundary therefore moves, within a quarter of a block's path of its
// equal-path place, to where a clock error of up to kMaxClockOffsetS (odometry/aligned_run.h)
// moves the ground truth's pose least. Measured (issue 40): the nominal's mean CF on the held-out
// blocks of the omni3 joystick run 0.133 -> 0.080; the first half of the diff drive's free run,
// refused before (its fit takes the other half's CF 0.057 -> 0.013), is written.

#include <vector>

#include "odometry/aligned_run.h"

namespace fitcal {

// Blocks k = 1..num_blocks of `run`, cut on its ground-truth track (AlignedRun::track), which
// each block keeps: id "<id>-block<k>", the run's trajectory label, repetition k. Throws
// std::invalid_argument when num_blocks < 1, the run has fewer samples than blocks or no track.
std::vector<AlignedRun> CutIntoTimeBlocks(const AlignedRun& run, int num_blocks);

}  // namespace fitcal
