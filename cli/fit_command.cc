#include "cli/fit_command.h"

#include <CLI/CLI.hpp>
#include <iostream>
#include <string>

#include "models/model_registry.h"
#include "cli/cli_validators.h"
#include "calibrate/fit_methods.h"
#include "cli/model_fit_command.h"
#include "io/output_guard.h"

namespace fitcal::tools {

void AddFitOptions(CLI::App& app, FitCommandOptions& o) {
  AddDatasetOptions(app, o, LogsFlag::kCheckedByCommand);
  app.add_option("--method", o.method, "Solver: " + FitMethodNames())->capture_default_str();
  AddSolverOptions(app, o);
  AddTrackResidualOptions(app, o);
  CLI::Option* reps =
      app.add_option("--train-reps", o.train_reps,
                     "Repetitions used for fitting, e.g. 1-5 or 1,3,5; the others validate")
          ->capture_default_str()
          ->check(RepetitionListValidator());
  app.add_option("--train-trajectories", o.train_trajectories,
                 "Fit on the runs whose trajectory label matches (list or regular expression); "
                 "the others validate")
      ->excludes(reps);
  CLI::Option* out = app.add_option("--out", o.out, "Calibrated robot YAML to write (atomically)")
                         ->capture_default_str();
  // An --out given with --no-output would be dropped: one of them is a mistake.
  app.add_flag("--no-output", o.no_output, "Do not write the calibrated YAML")->excludes(out);
  app.add_flag("--force", o.force, io::kForceFileHelp);
  app.add_option("--time-blocks", o.time_blocks,
                 "With one or two runs fitted on their tracks and none held out, judge on time: "
                 "cut each into this many blocks of equal path, fit the odd blocks and judge on "
                 "the even ones and back, pooled with 2, 4 and 8 blocks; the whole runs' fit is "
                 "written only when that beats the nominal")
      ->capture_default_str()
      ->check(CLI::Range(2, 100));
  app.add_flag("--bounds-widened", o.bounds_widened,
               "Write a calibration even when a parameter ends on its bound (after widening the "
               "robot YAML's bounds on purpose); without it such a fit is refused (exit 5)");
  app.add_flag("--skip-wheel-order-check", o.skip_wheel_order_check,
               "Fit even if another encoder column order/sign explains the data far better");
  app.add_option("--effects", o.effects,
                 "Library effects to fit with the parameters on the ground-truth tracks (e.g. "
                 "pivot_yaw_gain), one more candidate of the result gate; an effect the robot "
                 "YAML declares is refitted without naming it")
      ->delimiter(',');
  AddTyingFlags(app, o);
}

int RunFitCommand(const FitCommandOptions& options) {
  if (options.logs.empty()) {
    std::cerr << "fitcal: --logs <data set directory> is required (see fitcal --help)\n";
    return 2;
  }
  if (FindFitMethod(options.method) == nullptr) {
    std::cerr << "fitcal: unknown --method '" << options.method
              << "' (available: " << FitMethodNames() << ")\n";
    return 2;
  }
  FitMethodSettings settings;
  std::string settings_error;
  if (!MakeFitMethodSettings(options, options.threads, &settings, &settings_error)) {
    std::cerr << "fitcal: " << settings_error << "\n";
    return 2;
  }
  return RunReportingErrors("fitcal", [&]() -> int {
    const OpenedDataset opened = OpenDataset(options);
    if (!options.no_output) {
      // Every model's fit writes one file: never over one of its own inputs (exit 2, usage).
      const std::string refusal = io::OutputFileRefusal(options.out, opened.inputs);
      if (!refusal.empty()) return Refuse(refusal);
    }
    // One path for every model on the seam (models/model_interface.h), omni3 included.
    return RunModelFitCommand(options, opened.index, ReadRobotModelFile(opened.index.robot_path));
  });
}

}  // namespace fitcal::tools
