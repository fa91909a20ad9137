#pragma once
// `fitcal fit` (and plain `fitcal --logs ... --method ceres`): load a data set, fit on the
// training repetitions, validate on the rest, print the table and write the calibrated YAML.

#include <string>

#include "tools/dataset_command.h"

namespace fitcal::tools {

// --logs, --threads and --allow-outside-paths come from DatasetCommandOptions.
struct FitCommandOptions : DatasetCommandOptions {
  std::string method = "ceres";
  std::string train_reps = "1-5";
  // Non-empty: train on the runs whose trajectory label matches (validation/trajectory_split.h),
  // validate on the others; replaces train_reps.
  std::string train_trajectories;
  std::string out = "calibrated.yaml";
  bool no_output = false;
  bool force = false;  // overwrite --out even when it holds another robot's calibration
  bool skip_wheel_order_check = false;  // fit even if another column order fits far better
  double position_sigma_m = 1.0;
  double heading_sigma_deg = 180.0 / 3.14159265358979323846;  // 1 rad: Eq. 14's weighting
  // Solver settings (tools/fit_methods.h); each method uses those that apply to it.
  std::string objective;        // "" = the method's default; "squares" or "eq14"
  std::string loss = "none";    // Ceres: none, huber, cauchy
  double loss_scale = 0.05;     // Ceres robust loss scale, residual units
  unsigned long seed = 1;       // NLopt
  int max_evaluations = 20000;  // NLopt
  int max_iterations = 100;     // Ceres iterations per solve
  bool polish = false;          // NLopt global methods: SLSQP polish of the best point
};

// Declares every flag of `fit` on `app` (the `fit` subcommand, and the top level: `fitcal --logs
// DIR` without a subcommand fits), bound to `options`.
void AddFitOptions(CLI::App& app, FitCommandOptions& options);

// Returns the process exit code; prints results to stdout and errors (one line) to stderr.
int RunFitCommand(const FitCommandOptions& options);

}  // namespace fitcal::tools
