#pragma once
// `fitcal fit` for every robot model on the seam (models/model_interface.h), omni3 included: load
// the data set with the robot's channels, check it (rate units, channel order, degenerate data),
// fit on the training repetitions with any --method of calibrate/fit_methods.h (the bounded Ceres fit
// with its active set, fit/model_fit.h, or an NLopt search, fit/model_nlopt_fit.h), put the fit
// beside the nominal and the model's closed forms through the result gate (fit/result_gate.h),
// print the table and write the winner as the model's calibrated YAML (with its paper outputs,
// e.g. omni3's M^-1 of Palacin Eq. 6, models/omni3/omni3_robot_model.h).

#include <string>

#include "fit/result_gate.h"
#include "io/dataset.h"
#include "models/model_interface.h"
#include "cli/fit_command.h"

namespace fitcal::tools {

// Exit codes as README "Exit codes"; 5 when no candidate beats the nominal (nothing written).
int RunModelFitCommand(const FitCommandOptions& options, const io::DatasetIndex& index,
                       const RobotModelPtr& model);

}  // namespace fitcal::tools
