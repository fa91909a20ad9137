#pragma once
// `fitcal import optiodom <session-dir>... --out <dataset-dir>`: its flags, read into the import's
// options, and the one call (interchange/optiodom/optiodom_import.h) whose lines it prints.

#include "interchange/optiodom/optiodom_import.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

// Declares every flag of `import optiodom` on its subcommand `app`, bound to `options`.
void AddImportOptiOdomOptions(CLI::App& app, optiodom::ImportOptiOdomOptions& options);

int RunImportOptiOdomCommand(const optiodom::ImportOptiOdomOptions& options);

}  // namespace fitcal::tools
