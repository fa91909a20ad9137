#pragma once
// The everyday-driving table `fit` and `generalise` print (validation/everyday_driving.h): ATE
// RMSE (each run's start pose aligned, never a scale) and drift per 1, 2 and 5 m of ground-truth
// path, translation in % and rotation in deg/m, of the nominal robot and one calibration on the
// same runs, with the change in %. One function so that both commands print the same measure.

#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/effects.h"
#include "odometry/run_log.h"

namespace fitcal::tools {

// One side of the table: a parameter vector (the model's order) and the effects it replays with.
struct EverydayDrivingColumn {
  const std::vector<double>* parameters = nullptr;
  const std::vector<effects::EffectValue>* effects = nullptr;
};

// Prints "\n  <title>  nominal  calibrated  change" and one row per measure. tracks[i] is the
// ground truth of runs[i]. With `judge`, then the never-worse judgement of the calibration on
// these runs (validation/never_worse.h, the rule fit, diagnose and export refuse by): one line
// when it passes, one per measure that is worse beyond the runs' scatter.
void PrintEverydayDrivingTable(const RobotModelInterface& model,
                               const std::vector<AlignedRun>& runs,
                               const std::vector<const GroundTruthTrack*>& tracks,
                               const std::string& title, const EverydayDrivingColumn& nominal,
                               const EverydayDrivingColumn& calibrated, int threads,
                               bool judge = false);

}  // namespace fitcal::tools
