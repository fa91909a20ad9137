#pragma once
// `fitcal diagnose --logs <dir>`: the declared nine-parameter fit, its residual, the tracing of
// that residual to library effects (diagnosis/diagnose.h), the error before and after on held-out
// repetitions. Prints the report and writes, into --out (a directory):
//   index.html      the page (pages/diagnose_page.h): structure tested, effects tried, before and
//                   after on the held-out runs as `report` computes them, what stays unexplained
//   metrics.json    its numbers (docs/metrics_json.md, kind "diagnose")
//   diagnose.md     the report (Markdown)
//   calibrated.yaml the calibrated robot; carries the `effects:` list when effects were named
//   with --csv also residuals.csv (the pose error at every ground-truth sample of every run,
//                   after the tracing) and residuals_declared.csv (the declared fit's)

#include <string>

#include "cli/dataset_command.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

// --logs, --threads and --allow-outside-paths come from DatasetCommandOptions.
struct DiagnoseCommandOptions : DatasetCommandOptions {
  std::string train_reps = "auto";  // "auto": the first half of the repetitions present
  // Non-empty: split by trajectory label instead (fit/trajectory_split.h): matching runs
  // train, the others validate (e.g. "^circular" trains on circles and validates on squares).
  std::string train_trajectories;
  // Re-stamp each run's ground truth on the encoder clock first (fit/segment_cost.h,
  // EstimateClockMap): for recordings whose clocks were only mapped by hand.
  bool clock_map = false;
  // Re-stamp each clock group's ground truth by an offset estimated first (fit/clock_alignment.h:
  // a track fit of the parameters with one offset per session, run or the data set, on every
  // run; only the offsets are kept); "none" keeps the stamps.
  std::string clock_offsets = "none";
  std::string out = "diagnose";
  int max_effects = 3;
  double alpha = 0.01;
  bool csv = false;  // also write the residual CSVs (large: every ground-truth sample)
  bool skip_wheel_order_check = false;  // diagnose even if another channel order fits far better
};

// Declares every flag of `diagnose` on its subcommand `cmd`, bound to `options`.
void AddDiagnoseOptions(CLI::App& cmd, DiagnoseCommandOptions& options);
int RunDiagnoseCommand(const DiagnoseCommandOptions& options);

}  // namespace fitcal::tools
