#pragma once
// `fitcal report --logs <dir> --calibration <yaml> --out <dir>`: the validation report of a
// calibration on every run of the data set that did not train it (any data set: the calibrated
// YAML records its training runs by id), Palacin Sec. 3, Table 6, Fig. 9-10: a PASS / WARN / FAIL
// verdict (validation/verdict.h), trajectory metrics (Eq. 8-14) before and after, drift per
// distance, uncertainty and identifiability of the parameters, effects, optional
// leave-one-repetition-out cross-validation; writes index.html, summary.md, metrics.csv and
// metrics.json into --out (as a set, atomically).

#include <string>
#include <vector>

#include "cli/dataset_command.h"
#include "validation/report_builder.h"

namespace fitcal::tools {

// --logs, --threads and --allow-outside-paths come from DatasetCommandOptions.
struct ReportCommandOptions : DatasetCommandOptions {
  // Calibrated robot YAMLs; the first is reported in full, the others are compared with it on
  // the runs none of them trained on.
  std::vector<std::string> calibrations;
  std::string out;
  // Training repetitions; empty = as recorded in the calibration YAML, else "1-5".
  std::string train_reps;
  std::string sampling = "nearest";  // or "linear"
  bool cross_validate = false;
  // Exit status from the verdict (kReportFailExit, kReportWarnExit) instead of 0, for CI.
  bool strict = false;
  int worst_runs = 8;  // error-along-time figures drawn for this many of the worst runs
  // Also write tum/<run>.{ground_truth,nominal,calibrated}.tum for every judged run (io/tum_file.h,
  // docs/tum.md): the samples the drift and ATE figures of metrics.json are computed on.
  bool tum = false;
  // The ground truth's clock (fit/clock_alignment.h): the calibration's recorded offsets, none,
  // or offsets estimated here per session, run or data set with the calibrated parameters held.
  std::string clock_offsets = "recorded";
};

// Exit statuses of `report --strict` (README, exit codes): the report is written either way.
constexpr int kReportFailExit = 7;
constexpr int kReportWarnExit = 8;

// Returns the process exit code; errors are one line on stderr and nothing is written.
// Declares every flag of `report` on its subcommand `app`, bound to `options`.
void AddReportOptions(CLI::App& app, ReportCommandOptions& options);

int RunReportCommand(const ReportCommandOptions& options);

// ReportParameterOf and ReportEffectOf (the page rows diagnose shares) are in
// validation/report_builder.h.

}  // namespace fitcal::tools
