#pragma once
// Doebbler et al. Tables I and II by Monte Carlo (`fitcal paper-tables --model asoc`,
// docs/asoc.md): random true vehicles about the nominal, each driven through the calibration
// manoeuvre and the UMBmark square on the one simulator (the caller's `simulate`:
// sim/model_scenarios.h ScenarioSimulator with the castor dynamics of asoc_extras.h), calibrated by
// the closed form of Eq. 1-9 and judged by the odometry of the seam.

#include <vector>

#include "models/asoc/asoc_robot_model.h"
#include "models/model_extras.h"
#include "models/trajectory_spec.h"
#include "odometry/run_log.h"

namespace fitcal::asoc {

// UMBmark E_max (Borenstein; Doebbler Sec. IV-B): for each direction the distance of the mean of
// the runs' final position errors (odometry - truth) from zero; E_max the larger of the two.
double UmbmarkEmax(const RobotModelInterface& odometry, const std::vector<double>& p,
                   const std::vector<RunLog>& runs);

// The reproduction the asoc model registers (ModelExtras::paper_tables): the prototype's recorder
// with every run from the origin heading +x (UMBmark averages the runs' error vectors in the world
// frame) and the castors integrated at a tenth of the 20 Hz sample, as the paper's runs need; the
// tables printed in Markdown beside the paper's values.
PaperTables DoebblerPaperTables();

}  // namespace fitcal::asoc
