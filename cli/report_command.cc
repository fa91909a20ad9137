#include "cli/report_command.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <set>

#include "io/atomic_file.h"
#include "pages/report_csv.h"
#include "pages/report_html.h"
#include "pages/report_json.h"
#include "pages/report_markdown.h"
#include "pages/report_tum.h"
#include "io/staged_directory.h"
#include "models/model_registry.h"
#include "odometry/effects.h"
#include "cli/cli_validators.h"
#include "fit/clock_alignment.h"
#include "io/output_guard.h"
#include "validation/trajectory_metrics.h"

namespace fitcal::tools {

namespace {

const std::set<std::string> kReportFiles = {"index.html", "summary.md", "metrics.csv",
                                            "metrics.json", "tum"};

ReportInputs LoadInputs(const ReportCommandOptions& options, std::string* refusal) {
  ReportInputs in;
  OpenedDataset opened = OpenDataset(options);
  in.index = std::move(opened.index);
  in.inputs = std::move(opened.inputs);
  in.inputs.insert(in.inputs.end(), options.calibrations.begin(), options.calibrations.end());
  *refusal = io::OutputDirectoryRefusal(options.out, in.inputs, kReportFiles);
  if (!refusal->empty()) return in;
  in.model = ReadRobotModelFile(in.index.robot_path);
  // Loaded as `fit` loads them, with the robot's channels (their runs' fingerprints must agree).
  in.dataset = LoadRuns(options, in.index, in.model->robot());
  for (const std::string& path : options.calibrations) {
    in.calibrations.push_back(ReadCalibrationFor(path, in.model->robot()));
  }
  const CalibrationInput& first = in.calibrations.front();
  const std::string aligned =
      AlignGroundTruthClocks(options.clock_offsets, *in.model, &first.calibrated.nominal,
                             first.provenance, options.threads, &in.dataset.runs);
  if (!aligned.empty()) std::printf("%s\n", aligned.c_str());
  return in;
}

void WriteReport(const ReportCommandOptions& options, const ReportInputs& in,
                 const io::ReportData& data) {
  // Everything is computed; only now touch the output directory, as a set (README, "Nothing
  // lost"): the files go into a staged sibling renamed over the previous report, so a signal,
  // a full disk or a second writer never leaves a mix of old and new files.
  namespace fs = std::filesystem;
  io::StagedDirectory staged(options.out);
  const fs::path out(staged.path());
  io::WriteFileAtomically((out / "index.html").string(), io::ReportHtml(data));
  io::WriteFileAtomically((out / "summary.md").string(), io::ReportMarkdown(data));
  io::WriteFileAtomically((out / "metrics.csv").string(), io::MetricsCsv(data));
  if (options.tum) {
    fs::create_directories(out / "tum");
    for (const io::ReportFile& file : io::ReportTumFiles(data)) {
      io::WriteFileAtomically((out / file.relative_path).string(), file.text);
    }
  }
  io::StopHereForTests("report-staged");
  io::WriteFileAtomically((out / "metrics.json").string(), io::MetricsJson(data));
  io::CommitOutputDirectory(staged, options.out, in.inputs, kReportFiles);
}

void PrintReport(const ReportCommandOptions& options, const io::ReportData& data) {
  const io::ReportSummaryRow& all = data.summary.back();
  std::printf("validation: %zu run%s (repetitions %s), odometry sampled by %s time\n",
              data.runs.size(), data.runs.size() == 1 ? "" : "s",
              data.validation_repetitions.c_str(), data.sampling.c_str());
  std::printf("training: %s\n", data.training_source.c_str());
  // change = 100 (after - before) / before, the one sign of every % change of the report.
  std::printf("  CF (Eq. 14)            %.4f -> %.4f  (change %+.1f %%)\n", all.before.cf,
              all.after.cf, -ImprovementPercent(all.before.cf, all.after.cf));
  std::printf("  ATE RMSE [m] (Eq. 12)  %.4f -> %.4f  (change %+.1f %%)\n",
              all.before.rms_distance_m, all.after.rms_distance_m,
              -ImprovementPercent(all.before.rms_distance_m, all.after.rms_distance_m));
  const int worse = io::WorseRunCount(data);
  if (worse > 0)
    std::printf("  held-out runs that got worse: %d of %zu\n", worse, data.runs.size());
  for (const std::string& line : data.identifiability_lines) std::printf("%s\n", line.c_str());
  if (data.has_cv) {
    std::printf("cross-validation: %zu folds, validation CF %.4f +- %.4f (min %.4f, max %.4f)\n",
                data.folds.size(), data.cv_cf_after.mean, data.cv_cf_after.std,
                data.cv_cf_after.min, data.cv_cf_after.max);
    std::printf("  %s\n", data.cv_objective.c_str());
  }
  for (const io::ReportComparisonRow& c : data.comparison) {
    std::printf("  compared: %-40s %s  held-out CF %.4f -> %.4f\n", c.calibration.c_str(),
                c.verdict.c_str(), c.all.before.cf, c.all.after.cf);
  }
  std::printf("verdict: %s\n", data.verdict.c_str());
  for (const io::ReportVerdictReason& r : data.verdict_reasons) {
    std::printf("  %s %s: %s\n", r.level.c_str(), r.check.c_str(), r.message.c_str());
  }
  std::printf("wrote %s/{index.html, summary.md, metrics.csv, metrics.json%s}\n",
              options.out.c_str(), options.tum ? ", tum/" : "");
}

// --strict: the verdict as the exit status, for CI pipelines (README, exit codes).
int ExitStatus(const ReportCommandOptions& options, const std::string& verdict) {
  if (!options.strict || verdict == "PASS") return 0;
  return verdict == "FAIL" ? kReportFailExit : kReportWarnExit;
}

}  // namespace

void AddReportOptions(CLI::App& app, ReportCommandOptions& o) {
  AddDatasetOptions(app, o);
  app.add_option("--calibration", o.calibrations,
                 "Calibrated robot YAML (from fit or diagnose); repeat it to compare several "
                 "calibrations on the same runs (the first is reported in full)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--out", o.out, "Output directory for the report")->required();
  app.add_option("--train-reps", o.train_reps,
                 "Training repetitions of this data set (default: the runs the calibration "
                 "YAML records; on another data set every run validates)")
      ->check(RepetitionListValidator());
  app.add_option("--sampling", o.sampling,
                 "Odometry at ground-truth times: nearest (default, as the paper) or linear")
      ->capture_default_str();
  app.add_flag("--cv", o.cross_validate, "Also run leave-one-repetition-out cross-validation");
  app.add_flag("--strict", o.strict,
               "Exit 7 when the verdict is FAIL and 8 when it is WARN (the report is "
               "written either way), for CI pipelines");
  app.add_flag("--tum", o.tum,
               "Also write tum/<run>.{ground_truth,nominal,calibrated}.tum of every judged run "
               "(for evo_ape / evo_rpe; docs/tum.md)");
  app.add_option("--clock-offsets", o.clock_offsets,
                 "Ground-truth clock: the offsets the calibration records (recorded), none, or "
                 "estimated here per session, run or dataset with the calibrated parameters "
                 "held (docs/everyday_driving.md)")
      ->capture_default_str()
      ->check(CLI::IsMember({"recorded", "none", "session", "run", "dataset"}));
  app.add_option("--worst-runs", o.worst_runs,
                 "Draw the error along time of this many of the worst validation runs")
      ->capture_default_str()
      ->check(NonNegativeNumber());
}

int RunReportCommand(const ReportCommandOptions& options) {
  OdometrySampling sampling;
  if (options.sampling == "nearest") {
    sampling = OdometrySampling::kNearestTime;
  } else if (options.sampling == "linear") {
    sampling = OdometrySampling::kLinearInterpolation;
  } else {
    std::cerr << "fitcal report: unknown --sampling '" << options.sampling
              << "' (nearest or linear)\n";
    return 2;
  }
  return RunReportingErrors("fitcal report", [&]() -> int {
    std::string refusal;
    const ReportInputs in = LoadInputs(options, &refusal);
    if (!refusal.empty()) {
      return Refuse(refusal);
    }
    std::vector<TrainingSplit> splits = CommonSplits(options.train_reps, in);
    if (const std::string nothing = NothingToValidateRefusal(splits, options.logs);
        !nothing.empty()) {
      std::cerr << "fitcal report: " << nothing << "\n";
      return 2;
    }
    ReportBuildOptions build;
    build.dataset = options.logs;
    build.train_reps = options.train_reps;
    build.sampling = sampling;
    build.cross_validate = options.cross_validate;
    build.threads = options.threads;
    build.worst_runs = options.worst_runs;
    const io::ReportData data = BuildReport(in, std::move(splits), build);
    WriteReport(options, in, data);
    PrintReport(options, data);
    return ExitStatus(options, data.verdict);
  });
}

}  // namespace fitcal::tools
