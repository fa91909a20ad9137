#pragma once
// `fitcal compare --logs <dir>`: Palacin Table 4 regenerated on the user's data, for any robot
// model (the comparison itself is calibrate/method_comparison.h's CompareMethods) - every strategy
// (STA..STE or explicit trajectory lists, fit/strategies.h; "all" or a label prefix) x every method
// (calibrate/fit_methods.h) x training on the first 1 or 5 repetitions, validated on every
// trajectory of the held-out repetitions (Palacin Sec. 3.2: "five additional" repetitions of the
// whole flower). The model's closed forms (UMBmark for a differential drive) are rows beside the
// fits, computed from the same training runs. Prints the table as Markdown and writes <out>.csv,
// <out>.md and <out>_trace.csv (best CF vs evaluations per fit), each atomically, after every fit
// has finished; a file there that is not compare's previous output is refused (exit 2) unless
// --force (io/output_guard.h). With --tie/--hold (fit/parameter_tying.h, read as `fit` reads them)
// every method also fits the reduced model, a "<method> (tied)" row beside its full fit.

#include <string>
#include <vector>

#include "cli/dataset_command.h"
#include "cli/solver_options.h"
#include "cli/tying_flags.h"

namespace fitcal::tools {

// --logs, --threads and --allow-outside-paths come from DatasetCommandOptions, the solver flags
// from SolverOptions and --tie/--hold from TyingFlags (the same as fit's).
struct CompareCommandOptions : DatasetCommandOptions, SolverOptions, TyingFlags {
  // Palacin's STA..STE, trajectory lists, "all" or "<prefix>*" (calibrate/method_comparison.h).
  // Without strategies_given: those of STA..STE the data set has, else "all".
  std::vector<std::string> strategies = {"STA", "STB", "STC", "STD", "STE"};
  bool strategies_given = false;
  std::vector<std::string> methods = {"ceres", "crs2lm", "esch", "slsqp"};  // or "all"
  std::vector<int> repetitions = {1, 5};  // train on the first k repetitions of the data set
  std::string validation_reps;            // "" = every repetition after the largest k
  std::string out = "compare";            // prefix of the output files
  bool no_output = false;
  bool force = false;  // replace files at <out>.* that compare did not write (output_guard.h)
  bool quiet = false;

  // Each of the many fits compare runs gets half the NLopt budget of a single `fit`.
  CompareCommandOptions() { max_evaluations = 10000; }
};

// Returns the process exit code; the table goes to stdout, progress (on a terminal, unless
// quiet) and errors (one line) to stderr.
// Declares every flag of `compare` on its subcommand `app`, bound to `options`.
void AddCompareOptions(CLI::App& app, CompareCommandOptions& options);

int RunCompareCommand(const CompareCommandOptions& options);

}  // namespace fitcal::tools
