#include "cli/import_optiodom.h"

#include <CLI/CLI.hpp>
#include <cstdio>

#include "cli/dataset_command.h"
#include "io/output_guard.h"

namespace fitcal::tools {

void AddImportOptiOdomOptions(CLI::App& app, optiodom::ImportOptiOdomOptions& o) {
  app.add_option("sessions", o.sessions, "Session directories")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--out", o.out, "Output data set directory")->required();
  app.add_flag("--force", o.force, io::kForceDirectoryHelp);
  app.add_flag("--skip-mapping-check", o.skip_mapping_check,
               "Write even if another wheel order/sign explains the ground truth better");
}

int RunImportOptiOdomCommand(const optiodom::ImportOptiOdomOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int {
    const auto print = [](const std::string& line) { std::printf("%s\n", line.c_str()); };
    const optiodom::OptiOdomImport in = optiodom::ImportOptiOdom(options, print);
    print(optiodom::ImportSummary(in, options.out));
    return 0;
  });
}

}  // namespace fitcal::tools
