#pragma once
// The everyday-driving table `fit` and `generalise` print (validation/never_worse.h,
// CompareEverydayDriving): ATE RMSE (each run's start pose aligned, never a scale) and drift per
// 1, 2 and 5 m of ground-truth path, translation in % and rotation in deg/m, of the nominal robot
// and one calibration on the same runs, with the change in %. One function so that both commands
// print the same measure.

#include <string>

#include "validation/never_worse.h"

namespace fitcal::tools {

// Prints "\n  <title>  nominal  calibrated  change" and the comparison's rows. With `judge`, then
// the never-worse judgement of the calibration on these runs (the rule fit, diagnose and export
// refuse by): one line when it passes, one per measure that is worse beyond the runs' scatter.
void PrintEverydayDrivingTable(const std::string& title, const EverydayDrivingComparison& table,
                               bool judge = false);

}  // namespace fitcal::tools
