#pragma once
// `fitcal generalise --logs DIR`: how well a calibration transfers to runs it was not fitted on,
// for every robot model on the seam (models/model_interface.h), omni3 included. The splits and
// candidates are validation/generalisation.h's: train on one path type (the trajectory label up to
// its first '_' or '/', e.g. `circular` of `circular_221220201643`, as `fitcal import optiodom`
// writes them) and test on each other one, or a --train-trajectories selection against the rest;
// training repetitions of every path type against the others; leave-one-session-out. Printed as
// Markdown tables (train CF, held-out CF (Palacin Eq. 14), mean position and heading errors, held
// directions, parameters at a bound), then the everyday-driving measures `fit` prints
// (cli/everyday_driving_table.h: ATE RMSE, drift per 1, 2, 5 m) of the nominal and each fit on
// every split's held-out runs. With --tie/--hold (fit/parameter_tying.h, as `fit` takes them)
// each fit is made once more on the reduced model and judged beside the full one: "fit (tied)"
// and "fit (track, tied)" rows, columns of leave-one-session-out and everyday-driving tables.

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli/dataset_command.h"
#include "cli/tying_flags.h"

namespace fitcal::tools {

// --logs, --threads and --allow-outside-paths come from DatasetCommandOptions; --tie and --hold
// (TyingFlags, read as `fit` reads them) add the reduced model's fits beside the full ones.
struct GeneraliseCommandOptions : DatasetCommandOptions, TyingFlags {
  bool leave_one_session_out = true;
  // Non-empty: instead of every pair of path types, train on the runs whose trajectory label
  // matches (fit/trajectory_split.h: a list of labels or a regular expression) and test on
  // the others, then the other way round.
  std::string train_trajectories;
  // Library effects (odometry/effects.h names): "track fit" and "track fit + effects", fitted to
  // the training runs' ground-truth tracks (fit/effect_fit.h), join the candidates.
  std::vector<std::string> effects;
  // The repetitions that train the "every path type" split ("auto": the first half of those
  // present, fit/run_split.h), and what a session of leave-one-session-out is: "label" (the
  // trajectory label) or "repetition" (path type + repetition number, as the OptiOdom tricycle
  // import numbers its sessions).
  std::string train_reps = "auto";
  std::string sessions = "label";
  // Score the method published with the OptiOdom recordings as one more candidate
  // (validation/generalisation.h TrackCandidates; needs ground-truth tracks). Off by default: its
  // checkpoint cost costs more than the fit (omni4's leave-one-session-out 32 -> 60 s on one core).
  bool optiodom = false;
};

// Declares every flag of `generalise` on its subcommand `app`, bound to `options`.
void AddGeneraliseOptions(CLI::App& app, GeneraliseCommandOptions& options);

int RunGeneraliseCommand(const GeneraliseCommandOptions& options);

}  // namespace fitcal::tools
