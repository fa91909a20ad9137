#pragma once
// What a fit would not notice, checked before it: runs that stand still and rates in the wrong
// unit (exit 1), miswired channels (exit 4), data that cannot determine the parameters
// (warnings).

#include <string>
#include <vector>

#include "calibrate/calibration_request.h"
#include "fit/run_split.h"

namespace fitcal {

// 0 to go on (with the data's warnings appended to *warnings); else the exit code, with the
// refusal's reason in *reason.
int CheckBeforeFitting(const CalibrationRequest& request, const RobotModelInterface& model,
                       const RunSplit& split, std::vector<std::string>* warnings,
                       std::string* reason);

}  // namespace fitcal
