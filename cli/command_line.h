#pragma once
// fitcal's command line (cli/command_line.cc): the table of subcommands, the parser and its one
// line per usage error, the process-wide setup every command relies on.

namespace fitcal::tools {

// Silences the libraries' logging, installs the signal and input guards, parses `argv` and runs
// the subcommand it names (`fit` when none); returns the process's exit status.
int RunCommandLine(int argc, char** argv);

}  // namespace fitcal::tools
