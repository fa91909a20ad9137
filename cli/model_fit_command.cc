#include "cli/model_fit_command.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "calibrate/calibrate.h"
#include "calibrate/fit_methods.h"
#include "io/atomic_file.h"
#include "io/calibration_block.h"
#include "cli/effect_list.h"
#include "cli/fit_printout.h"
#include "io/output_guard.h"
#include "cli/tying_flags.h"

namespace fitcal::tools {

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

// A flag the fit asked for would not use: "" or the refusal's one line (exit 2), so that nothing
// the user set is dropped without a word. Defaults are those of SolverOptions (a flag given at its
// default changes nothing either way).
std::string FlagThatDoesNotApply(const FitCommandOptions& o) {
  const SolverOptions defaults;
  const bool ceres = IsCeresMethod(o.method);
  const std::string methods = "--method " + o.method;
  if (std::string e = SolverFlagThatDoesNotApply(o, defaults, ceres, !ceres, methods); !e.empty()) {
    return e;
  }
  const bool loss = o.loss != defaults.loss;
  if (o.residuals == "final-pose" && o.clock_offsets != defaults.clock_offsets) {
    return "--clock-offsets " + o.clock_offsets +
           " is estimated on track residuals; --residuals final-pose compares final poses, "
           "where no clock offset is estimated (--residuals track or both)";
  }
  if (o.residuals == "final-pose" && (o.track_heading != defaults.track_heading ||
                                      o.weight_mode != defaults.weight_mode)) {
    return std::string(o.track_heading != defaults.track_heading ? "--track-heading"
                                                                 : "--weights") +
           " shapes track residuals; --residuals final-pose compares final poses only "
           "(--residuals track or both)";
  }
  if (o.residuals == "track" && (loss || !o.objective.empty())) {
    return std::string(loss ? "--loss" : "--objective") +
           " shapes final-pose residuals; the track residual has its own fixed Huber loss "
           "(--residuals both fits final poses too)";
  }
  return "";
}

// What --residuals auto's choice leaves unused of the flags given, said beside the residuals:
// the clock offsets belong to the track, the loss and the objective to the final poses.
std::vector<std::string> FlagsTheChoiceLeavesUnused(const FitCommandOptions& o,
                                                    const CalibrationOutcome& outcome) {
  const FitMethodSettings& settings = outcome.settings;
  std::vector<std::string> notes;
  // --time-blocks: only one or two runs fitted on their tracks with nothing held out are judged
  // on time; otherwise the count given would change nothing.
  if (o.time_blocks != FitCommandOptions().time_blocks && !outcome.halves.by_time) {
    notes.push_back("note: --time-blocks " + std::to_string(o.time_blocks) +
                    " not applied: the fit was not judged on time blocks (only one or two runs "
                    "fitted on their tracks with no run held out are)");
  }
  if (!settings.residuals_auto) return notes;
  const SolverOptions defaults;
  if (settings.residuals == ResidualKind::kFinalPose && o.clock_offsets != defaults.clock_offsets) {
    notes.push_back("note: --clock-offsets " + o.clock_offsets +
                    " not applied: final-pose residuals were chosen, on which no clock offset "
                    "is estimated (--residuals track estimates it on dense ground truth)");
  }
  if (settings.residuals == ResidualKind::kFinalPose && o.track_heading != defaults.track_heading) {
    notes.push_back("note: --track-heading " + o.track_heading +
                    " not applied: final-pose residuals were chosen (it shapes track residuals)");
  }
  if (settings.residuals == ResidualKind::kFinalPose && o.weight_mode != defaults.weight_mode) {
    notes.push_back("note: --weights " + o.weight_mode +
                    " not applied: final-pose residuals were chosen (it weighs track residuals)");
  }
  if (settings.residuals == ResidualKind::kTrack && o.loss != defaults.loss) {
    notes.push_back("note: --loss " + o.loss +
                    " not applied: track residuals were chosen, which carry their own fixed "
                    "Huber loss (--residuals final-pose or both use --loss)");
  }
  if (settings.residuals == ResidualKind::kTrack && !o.objective.empty()) {
    notes.push_back("note: --objective " + o.objective +
                    " not applied: track residuals were chosen (it shapes final-pose residuals)");
  }
  return notes;
}

// The request's method, settings and effects from the flags, checked before anything is loaded.
// 0, or one line on stderr and the exit code (2 for a flag).
int ReadMethodAndEffects(const FitCommandOptions& options, const Robot& robot,
                         CalibrationRequest* request) {
  // Validated by RunFitCommand: a known method, settings in range.
  request->method = FindFitMethod(options.method);
  if (const std::string unused = FlagThatDoesNotApply(options); !unused.empty()) {
    std::cerr << "fitcal: " << unused << "\n";
    return 2;
  }
  std::string error;
  if (request->method == nullptr ||
      !MakeFitMethodSettings(options, options.threads, &request->settings, &error)) {
    std::cerr << "fitcal: "
              << (request->method == nullptr ? "unknown --method " + options.method : error)
              << "\n";
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
  if (const int refused = ReadMethodAndEffects(options, robot, request); refused != 0) {
    return refused;
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

}  // namespace

int RunModelFitCommand(const FitCommandOptions& options, const io::DatasetIndex& index,
                       const RobotModelPtr& model) {
  const auto t_total = std::chrono::steady_clock::now();
  CalibrationRequest request;
  if (const int refused = MakeRequest(options, model->robot(), &request); refused != 0) {
    return refused;
  }
  request.runs = LoadRuns(options, index, model->robot()).runs;
  io::StopHereForTests("loaded");
  const double load_s = Seconds(t_total);
  const CalibrationOutcome outcome = Calibrate(request, *model);
  PrintCalibrationOutcome(request, *model, outcome,
                          FlagsTheChoiceLeavesUnused(options, outcome));
  if (outcome.refusal.exit_code != 0) return outcome.refusal.exit_code;
  if (outcome.record) WriteCalibration(options, *model, outcome.selected(), *outcome.record);
  std::printf("time: load %.3f s, total %.3f s\n", load_s, Seconds(t_total));
  if (!outcome.stopped_early.empty()) std::cerr << "fitcal: " << outcome.stopped_early << "\n";
  return outcome.exit_code();
}

}  // namespace fitcal::tools
