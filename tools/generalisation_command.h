#pragma once
// `fitcal generalise --logs DIR`: how well a calibration transfers to paths it was not fitted on.
// Runs are grouped by path type (the trajectory label up to its first '_', e.g. `circular` of
// `circular_221220201643`, as `fitcal import optiodom` writes them) and by session (the whole
// trajectory label). For every model (nominal, nine parameters with the final-pose or the segment
// cost, the reduced common-distance + three-radii model) it prints:
//   - train on one path type, test on each other one (final-pose CF, Eq. 14, and segment CF);
//   - leave-one-session-out: fit on all other sessions, test on the one left out.
// The Markdown table it prints is the one in the README. Every other model on the seam goes
// through tools/model_generalise_command.h (nominal, closed forms and the fit; the same splits
// plus training repetitions against the rest).

#include <string>
#include <vector>

#include "tools/dataset_command.h"

namespace fitcal::tools {

// --logs, --threads and --allow-outside-paths come from DatasetCommandOptions.
struct GeneraliseCommandOptions : DatasetCommandOptions {
  double segment_length_m = 1.0;
  bool clock_map = true;  // refine each run's ground-truth clock before cutting segments
  bool leave_one_session_out = true;
  // Non-empty: instead of every pair of path types, train on the runs whose trajectory label
  // matches (fit/trajectory_split.h: a list of labels or a regular expression) and test on
  // the others, then the other way round.
  std::string train_trajectories;
  // Library effects (odometry/effects.h names) to add as a further model: "nine + effects",
  // fitted to the training runs' ground-truth tracks (fit/effect_fit.h) and scored on the
  // test runs' final poses (Eq. 14, replayed with the effects). "nine, track cost" is the same fit
  // without effects, the like-for-like baseline.
  std::vector<std::string> effects;
  // Models other than omni3 (tools/model_generalise_command.h): the repetitions that train the
  // "every path type" split ("" or "auto": the first half of those present), and what a session
  // of leave-one-session-out is: "label" (the trajectory label) or "repetition" (path type +
  // repetition number, as the OptiOdom tricycle import numbers its sessions).
  std::string train_reps;
  std::string sessions = "label";
  // Models other than omni3: score the method published with the OptiOdom recordings as one more
  // candidate (validation/generalisation.h TrackCandidates; needs ground-truth tracks). Off by
  // default: its checkpoint cost costs more than the fit (omni4's leave-one-session-out 32 -> 60
  // s on one core).
  bool optiodom = false;
};

// Declares every flag of `generalise` on its subcommand `app`, bound to `options`.
void AddGeneraliseOptions(CLI::App& app, GeneraliseCommandOptions& options);

int RunGeneraliseCommand(const GeneraliseCommandOptions& options);

}  // namespace fitcal::tools
