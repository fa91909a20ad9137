#include "cli/diagnose_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>

#include "calibrate/diagnosis_calibration.h"
#include "diagnosis/channel_order_check.h"
#include "diagnosis/clock_choice.h"
#include "diagnosis/diagnose.h"
#include "fit/segment_cost.h"
#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/calibration_block.h"
#include "io/dataset.h"
#include "pages/diagnose_page.h"
#include "io/input_error.h"
#include "io/robot_yaml_blocks.h"
#include "io/staged_directory.h"
#include "models/model_registry.h"
#include "odometry/text_format.h"
#include "cli/cli_validators.h"
#include "fit/clock_alignment.h"
#include "calibrate/diagnose_page_builder.h"
#include "diagnosis/miswired_error.h"
#include "io/output_guard.h"
#include "cli/report_command.h"
#include "validation/trajectory_metrics.h"

namespace fitcal::tools {

void AddDiagnoseOptions(CLI::App& cmd, DiagnoseCommandOptions& o) {
  AddDatasetOptions(cmd, o);
  CLI::Option* reps =
      cmd.add_option("--train-reps", o.train_reps,
                     "Training repetitions (e.g. 1-5); auto = the first half; the rest validate")
          ->capture_default_str()
          ->check(RepetitionListValidator(/*allow_auto=*/true));
  cmd.add_option("--train-trajectories", o.train_trajectories,
                 "Split by trajectory label instead: a list of labels or a regular expression "
                 "(e.g. ^circular); matching runs train, the others validate")
      ->excludes(reps);  // as fit: one split, not two that contradict each other
  cmd.add_flag("--clock-map", o.clock_map,
               "Re-stamp each run's ground truth on the encoder clock (speed-profile match)");
  cmd.add_option("--clock-offsets", o.clock_offsets,
                 "Re-stamp the ground truth by clock offsets estimated first per session, run or "
                 "dataset (a track fit of the parameters on every run; only the offsets are kept)")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "session", "run", "dataset"}));
  cmd.add_option("--out", o.out,
                 "Output directory (index.html, metrics.json, diagnose.md, calibrated.yaml)")
      ->capture_default_str();
  cmd.add_flag("--skip-wheel-order-check", o.skip_wheel_order_check,
               "Diagnose even if another channel order explains the runs far better");
  cmd.add_flag("--csv", o.csv,
               "Also write residuals.csv and residuals_declared.csv (every ground-truth sample)");
  cmd.add_option("--max-effects", o.max_effects, "Most effects to add")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  cmd.add_option("--alpha", o.alpha, "Family-wise significance level of the tracing")
      ->capture_default_str()
      ->check(CLI::Range(1e-9, 0.5));
}

namespace {

// Each reason on its own line of stderr; the refusal's exit status.
int PrintRefusal(const Refusal& refusal) {
  for (const std::string& reason : refusal.reasons) std::cerr << "fitcal: " << reason << "\n";
  return refusal.exit_code;
}

const std::set<std::string> kDiagnoseFiles = {"index.html",    "metrics.json",
                                              "diagnose.md",   "residuals.csv",
                                              "residuals_declared.csv", "calibrated.yaml"};

// The gate's table (calibrate/diagnosis_calibration.h), what the never-worse judgement and the
// uncertainty said, and the refusal's reasons.
void PrintDecision(const DiagnosisCalibration& c, std::size_t num_held_out) {
  std::printf("\nresult gate, CF on the held-out runs (%zu):\n", num_held_out);
  for (const DiagnoseChoice& d : c.gate) {
    std::printf("  %-28s %10.5f%s\n", d.name.c_str(), d.cf_after,
                d.name == c.choice.name ? "   <- selected" : "");
  }
  for (const std::string& line : c.never_worse_warnings) std::printf("warning: %s\n", line.c_str());
  if (c.uncertainty_propagated) {
    std::printf("uncertainty of '%s': propagated through the training runs' final poses\n",
                c.choice.name.c_str());
  }
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

// The one channel-order check (diagnosis/channel_order_check.h), as `fit` and the importers run
// it: a swapped or sign-flipped column would send the diagnosis after effects that are a wiring
// fault. True after one line on stderr when another order explains the runs far better.
bool ChannelsLookMiswired(const DiagnoseCommandOptions& options, const RobotModelInterface& model,
                          const std::vector<RunLog>& runs) {
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& run : runs) tracks.push_back(&run.ground_truth);
  ChannelOrderOptions order_options;
  order_options.num_threads = options.threads;
  const ChannelOrderReport order =
      CheckRecordedChannelOrder(AlignRuns(runs), tracks, model, order_options);
  if (!order.likely_miswired) return false;
  std::cerr << "fitcal: " << options.logs << ": " << order.message
            << "; nothing written (--skip-wheel-order-check to diagnose anyway)\n";
  return true;
}

void WriteOutputs(const DiagnoseCommandOptions& options, const std::vector<std::string>& inputs,
                  const std::string& report, const DiagnoseResult& result,
                  const io::DiagnosePageData& page, const std::string& yaml) {
  // Written as a set: staged, then renamed over the previous output (report_command.cc).
  io::StagedDirectory staged(options.out);
  const std::filesystem::path dir(staged.path());
  io::WriteFileAtomically((dir / "diagnose.md").string(), report);
  io::WriteFileAtomically((dir / "index.html").string(), io::DiagnoseHtml(page));
  if (options.csv) {
    io::WriteFileAtomically((dir / "residuals.csv").string(), ResidualSamplesCsv(result.after));
    io::WriteFileAtomically((dir / "residuals_declared.csv").string(),
                            ResidualSamplesCsv(result.before));
  }
  io::StopHereForTests("diagnose-staged");
  io::WriteFileAtomically((dir / "metrics.json").string(), io::DiagnoseMetricsJson(page));
  io::WriteFileAtomically((dir / "calibrated.yaml").string(), yaml);
  io::CommitOutputDirectory(staged, options.out, inputs, kDiagnoseFiles);
}

}  // namespace

int RunDiagnoseCommand(const DiagnoseCommandOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int {
    const OpenedDataset opened = OpenDataset(options);
    const io::DatasetIndex& index = opened.index;
    const std::vector<std::string>& inputs = opened.inputs;
    if (const std::string refusal = io::OutputDirectoryRefusal(options.out, inputs, kDiagnoseFiles);
        !refusal.empty()) {
      return Refuse(refusal);
    }
    const RobotModelPtr model = ReadRobotModelFile(index.robot_path);
    const Robot& robot = model->robot();
    if (const Refusal r = RefusalOfDeclaredEffects(robot, index.robot_path); r.exit_code != 0) {
      return PrintRefusal(r);
    }
    std::vector<RunLog> runs = LoadRuns(options, index, robot).runs;
    const std::string aligned = AlignGroundTruthClocks(options.clock_offsets, *model, nullptr,
                                                       std::nullopt, options.threads, &runs);
    if (!aligned.empty()) std::printf("%s\n", aligned.c_str());
    if (options.clock_map) {
      const ClockChoice clocks = MapGroundTruthClocks(*model, options.threads, &runs);
      std::printf("clock map kept on %d of %zu runs (the identity fits the others better)\n",
                  clocks.num_mapped, runs.size());
    }
    if (!options.skip_wheel_order_check && ChannelsLookMiswired(options, *model, runs)) {
      return kMiswiredExitCode;
    }
    const DiagnosisSplit split =
        SplitForDiagnosis(runs, robot, options.train_reps, options.train_trajectories);
    if (const Refusal r = RefusalOfSplit(split); r.exit_code != 0) return PrintRefusal(r);
    DiagnoseOptions diagnose_options;
    diagnose_options.fit.num_threads = options.threads;
    diagnose_options.max_effects = options.max_effects;
    diagnose_options.alpha = options.alpha;
    const DiagnoseResult result =
        Diagnose(split.training, split.validation, *model, diagnose_options);
    if (const Refusal r = RefusalOfUnconvergedFits(result); r.exit_code != 0) {
      return PrintRefusal(r);
    }
    const std::string report = "data set: " + options.logs + ", " + split.text +
                               (options.clock_map ? ", ground-truth clocks re-mapped" : "") +
                               ", fitcal " + kVersion + "\n\n" +
                               FormatDiagnoseReport(result, *model);
    std::printf("%s", report.c_str());
    const DiagnosisCalibration calibration = CalibrateOnDiagnosis(
        {options.logs, options.train_trajectories, &runs, options.threads}, *model, split, result);
    PrintDecision(calibration, split.validation.size());
    if (calibration.refusal.exit_code != 0) return PrintRefusal(calibration.refusal);
    const DiagnoseChoice& choice = calibration.choice;
    const std::string written = WrittenCalibrationText(robot, choice);
    std::printf("%s", written.c_str());
    // The model's own YAML with the accepted effects and the calibration block, as `fit` writes.
    const std::string yaml = model->RobotYaml(choice.parameters, choice.effects,
                                              io::CalibrationBlockYaml(calibration.record, robot));
    const io::DiagnosePageData page = MakeDiagnosePage(
        {options.logs, split.text, options.csv}, *model, split.validation, result, calibration,
        report);
    WriteOutputs(options, inputs, report + written, result, page, yaml);
    std::printf("\nheld-out runs as `report` computes them: CF %.4f -> %.4f\n",
                io::HeldOutMean(page.held_out, &io::DiagnoseHeldOutRun::cf_before),
                io::HeldOutMean(page.held_out, &io::DiagnoseHeldOutRun::cf_after));
    std::printf("\nwrote %s/{index.html, metrics.json, diagnose.md, calibrated.yaml%s}\n",
                options.out.c_str(), options.csv ? ", residuals.csv, residuals_declared.csv" : "");
    return 0;
  });
}

}  // namespace fitcal::tools
