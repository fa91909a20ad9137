#include "calibrate/diagnose_dataset.h"

#include "calibrate/diagnose_page_builder.h"
#include "calibrate/mount_freed.h"
#include "diagnosis/channel_order_check.h"
#include "diagnosis/clock_choice.h"
#include "diagnosis/miswired_error.h"
#include "fit/clock_alignment.h"
#include "fit/final_pose_errors.h"
#include "fitcal/version.h"
#include "io/calibration_block.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

// The one channel-order check (diagnosis/channel_order_check.h), as `fit` and the importers run
// it: a swapped or sign-flipped column would send the diagnosis after effects that are a wiring
// fault. The refusal when another order explains the runs far better.
Refusal MiswiredChannels(const DiagnoseDatasetRequest& request, const RobotModelInterface& model,
                         const std::vector<RunLog>& runs) {
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& run : runs) tracks.push_back(&run.ground_truth);
  ChannelOrderOptions order_options;
  order_options.num_threads = request.threads;
  const ChannelOrderReport order =
      CheckRecordedChannelOrder(AlignRuns(runs), tracks, model, order_options);
  if (!order.likely_miswired) return {};
  return {kMiswiredExitCode,
          {request.dataset + ": " + order.message +
           "; nothing written (--skip-wheel-order-check to diagnose anyway)"}};
}

// Re-stamps the runs' ground truth as asked; what it did, a line each.
std::vector<std::string> RestampClocks(const DiagnoseDatasetRequest& request,
                                       const RobotModelInterface& model,
                                       std::vector<RunLog>* runs) {
  std::vector<std::string> notes;
  const std::string aligned = AlignGroundTruthClocks(request.clock_offsets, model, nullptr,
                                                     std::nullopt, request.threads, runs);
  if (!aligned.empty()) notes.push_back(aligned);
  if (request.clock_map) {
    const ClockChoice clocks = MapGroundTruthClocks(model, request.threads, runs);
    notes.push_back(StrFormat("clock map kept on %d of %zu runs (the identity fits the others "
                              "better)",
                              clocks.num_mapped, runs->size()));
  }
  return notes;
}

// "## Written calibration": the chosen candidate's parameters with the sigma calibrated.yaml
// records, in display units.
std::string WrittenCalibrationText(const Robot& robot, const DiagnoseChoice& choice) {
  std::string out = "\n## Written calibration: " + choice.name +
                    "\n\n| parameter | unit | value | +-1 sigma |\n|---|---|---|---|\n";
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const ParameterInfo& info = robot.parameters[k];
    const double s = info.DisplayScale();
    // The unit has its own column (issue 42: "r_right [m] | m" said it twice).
    out += StrFormat("| %s%s | %s | %.6f | %.2g |\n", info.name.c_str(),
                     robot.IsHeld(k) ? " (held)" : "", info.DisplayUnit(), choice.parameters[k] * s,
                     choice.sigma[k] * s);
  }
  return out;
}

// The diagnosis' options from the request: its fits' and its tracing's.
DiagnoseOptions OptionsOf(const DiagnoseDatasetRequest& request) {
  DiagnoseOptions options;
  options.fit.num_threads = request.threads;
  options.max_effects = request.max_effects;
  options.alpha = request.alpha;
  return options;
}

// The diagnosis of the split's training runs, judged on its held-out runs; the report from it.
void DiagnoseSplit(const DiagnoseDatasetRequest& request, const RobotModelInterface& model,
                   DiagnoseDatasetOutcome* out) {
  out->result = Diagnose(out->split.training, out->split.validation, model, OptionsOf(request));
  out->refusal = RefusalOfUnconvergedFits(out->result);
  if (out->refusal.exit_code != 0) return;
  out->report = "data set: " + request.dataset + ", " + out->split.text +
                (request.clock_map ? ", ground-truth clocks re-mapped" : "") + ", fitcal " +
                kVersion + "\n\n" + FormatDiagnoseReport(out->result, model);
}

// The diagnosis of the split (DiagnoseSplit) and the calibration decided on it.
void DiagnoseAndCalibrate(const DiagnoseDatasetRequest& request, const RobotModelInterface& model,
                          const std::vector<RunLog>& runs, DiagnoseDatasetOutcome* out) {
  DiagnoseSplit(request, model, out);
  if (out->refusal.exit_code != 0) return;
  out->calibration =
      CalibrateOnDiagnosis({request.dataset, request.train_trajectories, &runs, request.threads},
                           model, out->split, out->result);
  out->refusal = out->calibration.refusal;
}

// fit's check (calibrate/mount_freed.h) on the diagnosis' base, the track fit: the same fit with
// the mount's x and y free, from the held one's point; when it predicts the training runs far
// better, the whole diagnosis is made again with them free and replaces the held one unless
// refused (stop 67's diagnose sweep: omni_040 and omni3_057, refused with the distances on their
// bounds, where `fit` frees the mount and calibrates them).
void DiagnoseAMountTheWheelsCannotAbsorb(const DiagnoseDatasetRequest& request,
                                         const RobotModelInterface& model,
                                         const std::vector<RunLog>& runs,
                                         DiagnoseDatasetOutcome* out) {
  const auto* mounted = dynamic_cast<const MountedModel*>(&model);
  const EffectFitResult& held = out->result.base;
  if (mounted == nullptr || !held.usable || out->refusal.exit_code == 3) return;
  const RobotModelPtr freed = mounted->WithSidewaysMountFreed();
  if (!freed) return;
  const EffectFitResult fitted =
      FitEffectModel(out->split.training, *freed, held.parameters, {}, OptionsOf(request).fit);
  if (!fitted.usable) return;
  const std::vector<AlignedRun> training = AlignedOf(out->split.training);
  const double held_cf =
      EvaluateFinalPoseErrors(model, held.parameters, training, request.threads).cf;
  const double free_cf =
      EvaluateFinalPoseErrors(*freed, fitted.parameters, training, request.threads).cf;
  if (!(free_cf < kMountFreedCfRatio * held_cf)) return;
  DiagnoseDatasetOutcome again;
  again.clock_notes = out->clock_notes;
  again.split = out->split;
  DiagnoseAndCalibrate(request, *freed, runs, &again);
  if (again.refusal.exit_code != 0) return;  // the held one's refusal names the guess
  again.mount_freed_line = MountFreedLine(*mounted, again.calibration.choice.parameters,
                                          held.parameters, held_cf, free_cf);
  again.mount_freed_model = freed;
  *out = std::move(again);
}

}  // namespace

DiagnoseDatasetOutcome DiagnoseDataset(const DiagnoseDatasetRequest& request,
                                       const RobotModelInterface& model, std::vector<RunLog> runs) {
  DiagnoseDatasetOutcome out;
  const Robot& robot = model.robot();
  out.refusal = RefusalOfDeclaredEffects(robot, request.robot_path);
  if (out.refusal.exit_code != 0) return out;
  out.clock_notes = RestampClocks(request, model, &runs);
  if (request.check_channel_order) out.refusal = MiswiredChannels(request, model, runs);
  if (out.refusal.exit_code != 0) return out;
  out.split = SplitForDiagnosis(runs, robot, request.train_reps, request.train_trajectories);
  out.refusal = RefusalOfSplit(out.split);
  if (out.refusal.exit_code != 0) return out;
  DiagnoseAndCalibrate(request, model, runs, &out);
  DiagnoseAMountTheWheelsCannotAbsorb(request, model, runs, &out);
  if (out.refusal.exit_code != 0) return out;
  const DiagnoseChoice& choice = out.calibration.choice;
  const RobotModelInterface& diagnosed = out.mount_freed_model ? *out.mount_freed_model : model;
  out.written_text = WrittenCalibrationText(diagnosed.robot(), choice);
  // The model's own YAML with the accepted effects and the calibration block, as `fit` writes.
  out.yaml =
      diagnosed.RobotYaml(choice.parameters, choice.effects,
                          io::CalibrationBlockYaml(out.calibration.record, diagnosed.robot()));
  out.page = MakeDiagnosePage({request.dataset, out.split.text, request.csv_written}, diagnosed,
                              out.split.validation, out.result, out.calibration, out.report);
  return out;
}

}  // namespace fitcal
