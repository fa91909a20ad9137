#pragma once
// `fit`'s flags against what the fit will use, so that nothing the user set is dropped without a
// word: a flag the request cannot use is refused before the runs are read (exit 2), one that
// --residuals auto's choice leaves unused is named in a note beside the residuals.

#include <string>
#include <vector>

#include "calibrate/calibrate.h"
#include "cli/fit_command.h"

namespace fitcal::tools {

// --closed-form-only runs no fit: "" or the one line refusing a flag only a fit uses.
std::string FitFlagBesideClosedForms(const FitCommandOptions& o);

// A flag the fit asked for would not use: "" or the refusal's one line. Defaults are those of
// SolverOptions (a flag given at its default changes nothing either way).
std::string FlagThatDoesNotApply(const FitCommandOptions& o);

// What --residuals auto's choice leaves unused of the flags given: the clock offsets belong to
// the track, the loss and the objective to the final poses.
std::vector<std::string> FlagsTheChoiceLeavesUnused(const FitCommandOptions& o,
                                                    const CalibrationOutcome& outcome);

}  // namespace fitcal::tools
