#pragma once
// The family of a trajectory label: the group the reports and the residual statistics summarise
// runs by (the paper's Table 6 rows R, G, B of the flower).

#include <string>

namespace fitcal {

// The label's leading letters: "R12" -> "R", "circular_2212" -> "circular", "hold_1_cw" -> "hold".
// A label that does not start with a letter is its own family; an empty one is "-".
std::string TrajectoryFamily(const std::string& label);

}  // namespace fitcal
