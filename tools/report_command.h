#pragma once
// `fitcal report --logs <dir> --calibration <yaml> --out <dir>`: the validation report of a
// calibration on the repetitions it was not fitted on (Palacin Sec. 3, Table 6, Fig. 9-10):
// trajectory metrics (Eq. 8-14) before and after, uncertainty and identifiability of the nine
// parameters, optional leave-one-repetition-out cross-validation; writes index.html, summary.md,
// metrics.csv and metrics.json into --out (each atomically).

#include <string>

namespace fitcal::tools {

struct ReportCommandOptions {
  std::string logs;
  std::string calibration;
  std::string out;
  // Training repetitions; empty = as recorded in the calibration YAML, else "1-5".
  std::string train_reps;
  std::string sampling = "nearest";  // or "linear"
  bool cross_validate = false;
  bool allow_outside_paths = false;
  int threads = 0;
};

// Returns the process exit code; errors are one line on stderr and nothing is written.
int RunReportCommand(const ReportCommandOptions& options);

}  // namespace fitcal::tools
