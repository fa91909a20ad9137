#pragma once
// The family of a trajectory label: the group the reports and the residual statistics summarise
// runs by (the paper's Table 6 rows R, G, B of the flower).

#include <map>
#include <string>
#include <vector>

#include "odometry/aligned_run.h"

namespace fitcal {

// The label's leading letters: "R12" -> "R", "circular_2212" -> "circular", "hold_1_cw" -> "hold".
// A label that does not start with a letter is its own family; an empty one is "-".
std::string TrajectoryFamily(const std::string& label);

// The runs grouped by their trajectory's family, in the order given within each family.
std::map<std::string, std::vector<AlignedRun>> RunsByFamily(const std::vector<AlignedRun>& runs);

// One line per family whose every run trains and none is held out (e.g. the one free run of an
// OptiOdom robot imported with its loops: repetition 1 trains), so that nothing judges the
// calibration on that kind of driving; empty when every family has a held-out run or nothing is
// held out at all. Said aloud, because the split by repetition decides it without a word.
std::vector<std::string> UnjudgedFamilyNotes(const std::vector<AlignedRun>& training,
                                             const std::vector<AlignedRun>& validation);

}  // namespace fitcal
