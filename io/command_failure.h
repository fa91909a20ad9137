#pragma once
// A command's failure that has an exit status of its own (README, exit codes): thrown where it is
// found, turned into one line `<prefix>: <what>` and that status by RunReportingErrors
// (cli/dataset_command.h), the one edge every command shares. Any other exception is bad
// input: status 1.

#include <stdexcept>
#include <string>

namespace fitcal {

// The exit statuses of every command, as `--help` shows them under each command (one footer, so
// that no command's help can drift from the README's list).
inline constexpr char kExitStatusHelp[] =
    "Exit status: 0 success; 1 bad input (one line: file:line: what is wrong); 2 usage error, or\n"
    "an output refused (README, Outputs: what may be replaced, with --force where a command has\n"
    "it); 3 the fit did not converge; 4 the encoder columns look miswired;\n"
    "5 no calibration beats the nominal robot on the held-out runs; 6 written with a warning\n"
    "(stopped at the iteration limit, or a global search short of a minimum); 7 and 8 report\n"
    "--strict judged FAIL and WARN. On any failure nothing is written.";

class CommandFailure : public std::runtime_error {
 public:
  CommandFailure(int exit_status, const std::string& what)
      : std::runtime_error(what), exit_status_(exit_status) {}
  int exit_status() const { return exit_status_; }

 private:
  int exit_status_;
};

// Status 2: a flag, a combination of flags or an output the command refuses.
class UsageError : public CommandFailure {
 public:
  explicit UsageError(const std::string& what) : CommandFailure(2, what) {}
};

// Status 5: no calibration beats the nominal robot on the judging runs.
class WorseThanNominalError : public CommandFailure {
 public:
  explicit WorseThanNominalError(const std::string& what) : CommandFailure(5, what) {}
};

}  // namespace fitcal
