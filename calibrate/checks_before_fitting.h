#pragma once
// What a fit would not notice, checked before it: runs that stand still and rates in the wrong
// unit (exit 1), miswired channels (exit 4), data that cannot determine the parameters
// (warnings).

#include <string>
#include <vector>

#include "calibrate/calibration_request.h"
#include "fit/run_split.h"

namespace fitcal {

// The runs among `runs` whose ids `training_ids` lists, when they stand still
// (diagnosis/degenerate_data.h StillRunsRefusal): "" or the refusal's one line, `dataset: ...`
// (exit 1). Every command that fits training runs asks it: fit and diagnose.
std::string StillTrainingRunsRefusal(const std::string& dataset, const std::vector<RunLog>& runs,
                                     const std::vector<std::string>& training_ids,
                                     const Robot& robot);

// 0 to go on (with the data's warnings appended to *warnings); else the exit code, with the
// refusal's reason in *reason.
int CheckBeforeFitting(const CalibrationRequest& request, const RobotModelInterface& model,
                       const RunSplit& split, std::vector<std::string>* warnings,
                       std::string* reason);

}  // namespace fitcal
