#include "cli/paper_tables_command.h"

#include <cstdio>

#include "cli/cli_validators.h"
#include "cli/dataset_command.h"
#include "sim/model_scenarios.h"

namespace fitcal::tools {

void AddPaperTablesOptions(CLI::App& app, PaperTablesOptions& o) {
  app.add_option("--model", o.model, "Robot model that reproduces a paper's tables")->required();
  app.add_option("--sets", o.sets, "Random parameter sets")
      ->capture_default_str()
      ->check(PositiveNumber());
  app.add_option("--seed", o.seed, "Random seed")->capture_default_str();
  app.add_option("--wheel-slip-sigma", o.wheel_slip_sigma,
                 "Relative wheel-encoder noise per encoder sample (non-systematic error)")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  app.add_option("--threads", o.threads, "Worker threads (0 = all cores)")->capture_default_str();
}

int RunPaperTablesCommand(const PaperTablesOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int {
    std::fputs(sim::ReproducePaperTables(options.model, options).c_str(), stdout);
    return 0;
  });
}

}  // namespace fitcal::tools
