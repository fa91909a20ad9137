#pragma once
// `fitcal fit` for every robot model on the seam (models/model_interface.h): load the data set
// with the robot's channels, fit on the training repetitions with any --method of
// tools/fit_methods.h (the bounded Ceres fit with its active set, fit/model_fit.h, or an NLopt
// search, fit/model_nlopt_fit.h), put the fit beside the nominal and the model's closed forms
// through the result gate (fit/result_gate.h), print the table and write the winner as a
// calibrated YAML.

#include <string>

#include "fit/result_gate.h"
#include "fit/run_split.h"
#include "io/calibration_block.h"
#include "io/dataset.h"
#include "models/model_interface.h"
#include "tools/fit_command.h"

namespace fitcal::tools {

// One line of the fit's output per direction held at the nominal (fit/determined_directions.h),
// the same for omni3's fit and every other model's.
void PrintHeldAtNominal(const std::string& direction);

// The result gate's table (fit/result_gate.h), the same for omni3's fit and every other model's,
// then effects_line (whether the effects earned their place) when not empty; false, with one line
// on stderr, when no candidate beats the nominal (exit 5, nothing written).
bool PrintGate(const std::vector<CalibrationCandidate>& candidates, const GateDecision& gate,
               const std::string& effects_line = "");

// The `calibration:` keys omni3's fit and every other model's record alike: the method the result
// gate selected, the fit's objective with the weights, the data set, the fit's termination and
// the training and held-out runs (logs: all of them, for the training runs' fingerprint).
void RecordFitSource(const FitCommandOptions& options, const std::vector<RunLog>& logs,
                     const RunSplit& split, const std::string& method, const std::string& objective,
                     const std::string& termination, io::CalibrationSource* source);

// Exit codes as README "Exit codes"; 5 when no candidate beats the nominal (nothing written).
int RunModelFitCommand(const FitCommandOptions& options, const io::DatasetIndex& index,
                       const RobotModelPtr& model);

// Exit 6 with a one-line warning when the written calibration is a fit that stopped at the
// iteration limit (it beat the nominal in the gate, but the solver did not converge); else 0.
int StoppedEarlyExit(bool selected_fit_stopped_early, const std::string& termination);

}  // namespace fitcal::tools
