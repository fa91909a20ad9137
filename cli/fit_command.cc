#include "cli/fit_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>

#include "calibrate/calibrate.h"
#include "calibrate/fit_methods.h"
#include "cli/cli_validators.h"
#include "cli/effect_list.h"
#include "cli/fit_flags.h"
#include "cli/fit_printout.h"
#include "io/atomic_file.h"
#include "io/calibration_block.h"
#include "io/output_guard.h"
#include "io/text_file.h"
#include "models/model_registry.h"

namespace fitcal::tools {

// The models that register closed forms, each with its methods: "<model>: <method>; ...".
std::string ClosedFormsOfModels() {
  std::vector<std::string> models;
  for (const ModelRegistration& m : RegisteredModels()) {
    std::vector<std::string> methods;
    for (const ClosedForm& form : m.extras.closed_forms) methods.push_back(form.method);
    if (!methods.empty()) models.push_back(m.name + ": " + io::Joined(methods, ", "));
  }
  std::sort(models.begin(), models.end());
  return io::Joined(models, "; ");
}

void AddFitOptions(CLI::App& app, FitCommandOptions& o) {
  AddDatasetOptions(app, o, LogsFlag::kCheckedByCommand);
  app.add_option("--method", o.method, "Solver: " + FitMethodNames())->capture_default_str();
  AddSolverOptions(app, o);
  AddTrackResidualOptions(app, o);
  CLI::Option* reps =
      app.add_option("--train-reps", o.train_reps,
                     "Repetitions used for fitting (or the closed forms), e.g. 1-5 or 1,3,5; the "
                     "others validate")
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
  app.add_flag("--closed-form-only", o.closed_forms_only,
               "No fit: the model's closed-form calibrations alone against the nominal, through "
               "the same gate (" + ClosedFormsOfModels() + ")");
  RecordGivenFlags(app, &o.given);
}

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The effects a fit refits: those the robot declares (their values start the fit) and the ones
// --effects names; nullopt after one line on stderr for a name ReadEffectList refuses.
std::optional<EffectModel> EffectsToFit(const FitCommandOptions& options, const Robot& robot) {
  const std::optional<EffectModel> named = ReadEffectList(options.effects, robot, "fit");
  if (!named) return std::nullopt;
  EffectModel out = robot.effects;
  for (const effects::EffectValue& e : *named) {
    const bool declared = std::any_of(out.begin(), out.end(),
                                      [&e](const effects::EffectValue& d) { return d.id == e.id; });
    if (!declared) out.push_back(e);
  }
  return out;
}

// The request's tying and effects from the flags (its method and settings RunFitCommand read),
// checked before the runs are loaded. 0, or one line on stderr and the exit code (2 for a flag).
int ReadTyingAndEffects(const FitCommandOptions& options, const Robot& robot,
                        CalibrationRequest* request) {
  if (const std::string unused = FlagThatDoesNotApply(options); !unused.empty()) {
    std::cerr << "fitcal: " << unused << "\n";
    return 2;
  }
  if (const std::string refusal = ReadTying(options, robot, &request->settings.tying);
      !refusal.empty()) {
    return Refuse(refusal);
  }
  const std::optional<EffectModel> effects_to_fit = EffectsToFit(options, robot);
  if (!effects_to_fit) return 2;
  if (!request->settings.tying.empty() && !effects_to_fit->empty()) {
    return Refuse("--tie and --hold apply to the parameters' fit, not to the effect fit (--effects "
                  "or effects the robot YAML declares), which moves every parameter");
  }
  request->effects_to_fit = *effects_to_fit;
  return 0;
}

// The calibration request of the flags (the runs are loaded after); else one line on stderr and
// the exit code (2 for a flag, the overwrite refusal's for an output fitcal did not write).
int MakeRequest(const FitCommandOptions& options, const Robot& robot,
                CalibrationRequest* request) {
  if (const int refused = ReadTyingAndEffects(options, robot, request); refused != 0) {
    return refused;
  }
  if (options.closed_forms_only && ExtrasOf(robot.model).closed_forms.empty()) {
    std::cerr << "fitcal: --closed-form-only: the " << robot.model
              << " model computes no closed form (models that do: " << ClosedFormsOfModels()
              << ")\n";
    return 2;
  }
  if (!options.no_output && !options.force) {
    const std::string refusal = io::OverwriteRefusal(options.out, robot.name);
    if (!refusal.empty()) return Refuse(refusal);
  }
  request->dataset = options.logs;
  request->train_reps = options.train_reps;
  request->train_trajectories = options.train_trajectories;
  request->threads = options.threads;
  request->time_blocks = options.time_blocks;
  request->position_sigma_m = options.position_sigma_m;
  request->heading_sigma_deg = options.heading_sigma_deg;
  request->check_channel_order = !options.skip_wheel_order_check;
  request->will_write = !options.no_output;
  request->bounds_widened = options.bounds_widened;
  request->closed_forms_only = options.closed_forms_only;
  return 0;
}

void WriteCalibration(const FitCommandOptions& options, const RobotModelInterface& model,
                      const CalibrationCandidate& selected, const io::CalibrationBlock& record) {
  io::StopHereForTests("fitted");
  io::WriteFileAtomically(options.out,
                          model.RobotYaml(selected.parameters, selected.effects,
                                          io::CalibrationBlockYaml(record, model.robot())));
  std::printf("wrote %s\n", options.out.c_str());
}

// `fitcal fit` for every robot model on the seam (models/model_interface.h), omni3 included: the
// runs loaded with the robot's channels, one Calibrate call (calibrate/calibrate.h: the checks,
// the fit of any --method, the result gate), its outcome printed and the winner written as the
// model's calibrated YAML. Exit codes as README "Exit codes".
int RunModelFitCommand(const FitCommandOptions& options, const io::DatasetIndex& index,
                       const RobotModelPtr& model, CalibrationRequest request) {
  const auto t_total = std::chrono::steady_clock::now();
  if (const int refused = MakeRequest(options, model->robot(), &request); refused != 0) {
    return refused;
  }
  request.runs = LoadRuns(options, index, model->robot()).runs;
  io::StopHereForTests("loaded");
  const double load_s = Seconds(t_total);
  const CalibrationOutcome outcome = Calibrate(request, *model);
  const RobotModelInterface& calibrated = outcome.CalibratedModel(*model);
  PrintCalibrationOutcome(request, calibrated, outcome,
                          FlagsTheChoiceLeavesUnused(options, outcome));
  if (outcome.refusal.exit_code != 0) return outcome.refusal.exit_code;
  if (outcome.record) WriteCalibration(options, calibrated, outcome.selected(), *outcome.record);
  std::printf("time: load %.3f s, total %.3f s\n", load_s, Seconds(t_total));
  if (!outcome.stopped_early.empty()) std::cerr << "fitcal: " << outcome.stopped_early << "\n";
  return outcome.exit_code();
}

}  // namespace

int RunFitCommand(const FitCommandOptions& options) {
  if (options.logs.empty()) {
    std::cerr << "fitcal: --logs <data set directory> is required (see fitcal --help)\n";
    return 2;
  }
  CalibrationRequest request;
  request.method = FindFitMethod(options.method);
  if (request.method == nullptr) {
    std::cerr << "fitcal: unknown --method '" << options.method
              << "' (available: " << FitMethodNames() << ")\n";
    return 2;
  }
  std::string settings_error;
  if (!MakeFitMethodSettings(options, options.threads, &request.settings, &settings_error)) {
    std::cerr << "fitcal: " << settings_error << "\n";
    return 2;
  }
  if (const std::string e = options.closed_forms_only ? FitFlagBesideClosedForms(options) : "";
      !e.empty()) {
    std::cerr << "fitcal: " << e << "\n";
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
    return RunModelFitCommand(options, opened.index, ReadRobotModelFile(opened.index.robot_path),
                              request);
  });
}

}  // namespace fitcal::tools
