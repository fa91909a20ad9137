#pragma once
// `fitcal generalise --logs DIR`: how well a calibration transfers to runs it was not fitted on,
// for every robot model on the seam; what it computes and decides is calibrate/generalise.h.
// Printed as Markdown tables (train CF, held-out CF (Palacin Eq. 14), mean position and heading
// errors, held directions, parameters at a bound), then the everyday-driving measures `fit`
// prints (cli/everyday_driving_table.h) of the nominal and each fit on every split's held-out
// runs. With --tie/--hold (as `fit` takes them) each fit is made once more on the reduced model:
// "fit (tied)" and "fit (track, tied)" rows and columns.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "calibrate/generalise.h"
#include "cli/dataset_command.h"
#include "cli/tying_flags.h"

namespace fitcal::tools {

// --logs, --threads and --allow-outside-paths come from DatasetCommandOptions; --tie and --hold
// (TyingFlags, read as `fit` reads them) add the reduced model's fits beside the full ones.
struct GeneraliseCommandOptions : DatasetCommandOptions, TyingFlags, GeneraliseOptions {
  // Library effects (odometry/effects.h names): "track fit" and "track fit + effects", fitted to
  // the training runs' ground-truth tracks (fit/effect_fit.h), join the candidates.
  std::vector<std::string> effects;
  // What a session of leave-one-session-out is: "label" (the trajectory label) or "repetition"
  // (path type + repetition number, as the OptiOdom tricycle import numbers its sessions).
  std::string sessions = "label";
};

// Declares every flag of `generalise` on its subcommand `app`, bound to `options`.
void AddGeneraliseOptions(CLI::App& app, GeneraliseCommandOptions& options);

int RunGeneraliseCommand(const GeneraliseCommandOptions& options);

}  // namespace fitcal::tools
