#pragma once
// `fitcal paper-tables --model <name>`: a paper's tables reproduced in simulation by the model
// that registers them (ModelExtras::paper_tables; asoc: Doebbler et al. Tables I and II,
// docs/asoc.md), printed as the model formats them.

#include <CLI/CLI.hpp>
#include <string>

#include "models/model_extras.h"

namespace fitcal::tools {

struct PaperTablesOptions : PaperTablesRequest {
  std::string model;
};

void AddPaperTablesOptions(CLI::App& app, PaperTablesOptions& options);
int RunPaperTablesCommand(const PaperTablesOptions& options);

}  // namespace fitcal::tools
