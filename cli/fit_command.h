#pragma once
// `fitcal fit` (and plain `fitcal --logs ... --method ceres`): load a data set, fit on the
// training repetitions, validate on the rest, print the table and write the calibrated YAML.

#include <set>
#include <string>
#include <vector>

#include "cli/dataset_command.h"
#include "cli/solver_options.h"
#include "cli/tying_flags.h"

namespace fitcal::tools {

// --logs, --threads and --allow-outside-paths come from DatasetCommandOptions, the solver flags
// from SolverOptions, --tie and --hold (fit/parameter_tying.h) from TyingFlags.
struct FitCommandOptions : DatasetCommandOptions, SolverOptions, TyingFlags {
  std::string method = "ceres";
  std::string train_reps = "1-5";
  // Non-empty: train on the runs whose trajectory label matches (fit/trajectory_split.h),
  // validate on the others; replaces train_reps.
  std::string train_trajectories;
  std::string out = "calibrated.yaml";
  bool no_output = false;
  bool force = false;  // overwrite --out even when it holds another robot's calibration
  bool skip_wheel_order_check = false;  // fit even if another column order fits far better
  // Library effects (odometry/effects.h) to fit with the parameters on the training tracks, as
  // one more candidate of the result gate; the effects a robot YAML declares are refitted too.
  std::vector<std::string> effects;
  // One or two runs fitted on their tracks and nothing held out: the procedure is judged on
  // held-out time blocks of equal path, 2, 4, 8 and this many per run, the fit of the odd blocks
  // on the even ones and back (validation/held_out_halves.h); the whole runs' fit is what is
  // written (on the OptiOdom free runs half a run calibrates worse, docs/everyday_driving.md).
  int time_blocks = 4;
  // Write a calibration with a parameter on its bound (fit/result_gate.h AtBoundRefusal): the user
  // widened the bounds on purpose and accepts a value that still ends on one.
  bool bounds_widened = false;
  // --closed-form-only: the robot's closed forms alone against the nominal, no fit
  // (CalibrationRequest::closed_forms_only); refused before the runs are read for a model that
  // registers none (ModelExtras::closed_forms) and beside a flag only a fit uses.
  bool closed_forms_only = false;
  std::set<std::string> given;  // the flags given on the command line, e.g. "--method"
};

// Declares every flag of `fit` on `app` (the `fit` subcommand, and the top level: `fitcal --logs
// DIR` without a subcommand fits), bound to `options`.
void AddFitOptions(CLI::App& app, FitCommandOptions& options);

// Returns the process exit code; prints results to stdout and errors (one line) to stderr.
int RunFitCommand(const FitCommandOptions& options);

}  // namespace fitcal::tools
