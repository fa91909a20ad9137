#include "cli/diagnose_command.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>

#include "calibrate/diagnose_dataset.h"
#include "cli/cli_validators.h"
#include "io/atomic_file.h"
#include "io/output_guard.h"
#include "io/staged_directory.h"
#include "models/model_registry.h"
#include "pages/diagnose_page.h"

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
  if (!c.left_out_line.empty()) std::printf("%s\n", c.left_out_line.c_str());
  if (!c.gave_way_line.empty()) std::printf("%s\n", c.gave_way_line.c_str());
  for (const std::string& line : c.never_worse_warnings) std::printf("warning: %s\n", line.c_str());
  if (c.uncertainty_propagated) {
    std::printf("uncertainty of '%s': propagated through the training runs' final poses\n",
                c.choice.name.c_str());
  }
  for (const std::string& line : c.sigma_notes) std::printf("resolution: %s\n", line.c_str());
}

// The library's request from the flags.
DiagnoseDatasetRequest DiagnoseRequest(const DiagnoseCommandOptions& options,
                                       const std::string& robot_path) {
  DiagnoseDatasetRequest r;
  r.dataset = options.logs;
  r.robot_path = robot_path;
  r.train_reps = options.train_reps;
  r.train_trajectories = options.train_trajectories;
  r.clock_offsets = options.clock_offsets;
  r.clock_map = options.clock_map;
  r.check_channel_order = !options.skip_wheel_order_check;
  r.csv_written = options.csv;
  r.threads = options.threads;
  r.max_effects = options.max_effects;
  r.alpha = options.alpha;
  return r;
}

void WriteOutputs(const DiagnoseCommandOptions& options, const std::vector<std::string>& inputs,
                  const DiagnoseDatasetOutcome& outcome) {
  // Written as a set: staged, then renamed over the previous output (report_command.cc).
  io::StagedDirectory staged(options.out);
  const std::filesystem::path dir(staged.path());
  io::WriteFileAtomically((dir / "diagnose.md").string(), outcome.report + outcome.written_text);
  io::WriteFileAtomically((dir / "index.html").string(), io::DiagnoseHtml(outcome.page));
  if (options.csv) {
    io::WriteFileAtomically((dir / "residuals.csv").string(),
                            ResidualSamplesCsv(outcome.result.after));
    io::WriteFileAtomically((dir / "residuals_declared.csv").string(),
                            ResidualSamplesCsv(outcome.result.before));
  }
  io::StopHereForTests("diagnose-staged");
  io::WriteFileAtomically((dir / "metrics.json").string(), io::DiagnoseMetricsJson(outcome.page));
  io::WriteFileAtomically((dir / "calibrated.yaml").string(), outcome.yaml);
  io::CommitOutputDirectory(staged, options.out, inputs, kDiagnoseFiles);
}

}  // namespace

int RunDiagnoseCommand(const DiagnoseCommandOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int {
    const OpenedDataset opened = OpenDataset(options);
    if (const std::string refusal =
            io::OutputDirectoryRefusal(options.out, opened.inputs, kDiagnoseFiles);
        !refusal.empty()) {
      return Refuse(refusal);
    }
    const RobotModelPtr model = ReadRobotModelFile(opened.index.robot_path);
    const DiagnoseDatasetOutcome outcome =
        DiagnoseDataset(DiagnoseRequest(options, opened.index.robot_path), *model,
                        LoadRuns(options, opened.index, model->robot()).runs);
    for (const std::string& note : outcome.clock_notes) std::printf("%s\n", note.c_str());
    std::printf("%s", outcome.report.c_str());
    if (!outcome.calibration.gate.empty()) {
      PrintDecision(outcome.calibration, outcome.split.validation.size());
    }
    if (!outcome.mount_freed_line.empty()) {
      std::printf("warning: %s\n", outcome.mount_freed_line.c_str());
    }
    if (outcome.refusal.exit_code != 0) return PrintRefusal(outcome.refusal);
    std::printf("%s", outcome.written_text.c_str());
    WriteOutputs(options, opened.inputs, outcome);
    const io::DiagnosePageData& page = outcome.page;
    std::printf("\nheld-out runs as `report` computes them: CF %.4f -> %.4f\n",
                io::HeldOutMean(page.held_out, &io::DiagnoseHeldOutRun::cf_before),
                io::HeldOutMean(page.held_out, &io::DiagnoseHeldOutRun::cf_after));
    std::printf("\nwrote %s/{index.html, metrics.json, diagnose.md, calibrated.yaml%s}\n",
                options.out.c_str(), options.csv ? ", residuals.csv, residuals_declared.csv" : "");
    return 0;
  });
}

}  // namespace fitcal::tools
