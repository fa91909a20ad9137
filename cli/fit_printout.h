#pragma once
// What `fitcal fit` prints of a calibration (calibrate/calibrate.h): on stdout, stage by stage as
// far as the calibration went, the data's warnings, the run split, the CF table, the parameters
// with their uncertainty, the solver, the residuals and their choice, everyday driving, the gate,
// the held-out judgements; on stderr, the refusal's reasons and the notes. No decision is made
// here.

#include <string>
#include <vector>

#include "calibrate/calibrate.h"

namespace fitcal::tools {

// `flag_notes`: lines said beside the residuals' choice (flags the choice leaves unused).
void PrintCalibrationOutcome(const CalibrationRequest& request, const RobotModelInterface& model,
                             const CalibrationOutcome& outcome,
                             const std::vector<std::string>& flag_notes);

}  // namespace fitcal::tools
