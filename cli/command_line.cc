// fitcal's command line: every subcommand is one row of the table in Commands() below - its name,
// what it does, the function that declares its flags and the one that runs it. `fitcal --logs <dir>
// --method ceres` without a subcommand runs `fit`. cli/fitcal_main.cc only calls
// RunCommandLine; this file is in the commands library so that it compiles in one of its batches
// (CMakeLists.txt fitcal_compile_in_batches): CLI11's inline code, which every command file
// already instantiates, cost 17.7 s of CPU at -O3 and 28.7 s instrumented as a file of its own.

#include <glog/logging.h>
#include <signal.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/input_error.h"
#include "io/input_registry.h"
#include "odometry/memory_reuse.h"
#include "cli/command_line.h"
#include "cli/cli_validators.h"
#include "io/command_failure.h"
#include "cli/compare_command.h"
#include "cli/diagnose_command.h"
#include "cli/export_ros2_control.h"
#include "cli/fit_command.h"
#include "cli/fleet_command.h"
#include "cli/import_optiodom.h"
#include "cli/import_rosbag2.h"
#include "cli/model_generalise_command.h"
#include "cli/paper_tables_command.h"
#include "cli/report_command.h"
#include "cli/simulate_command.h"

namespace fitcal::tools {
// The helpers are in a named namespace: the files of one batch share one anonymous namespace.
namespace command_line {

// One subcommand: `group` is the parent command (import, export) or empty for a top-level one.
// `add_options` declares the flags on the subcommand, bound to options that `run` then reads; both
// close over the same options object (MakeCommand).
struct Command {
  std::string group;
  std::string name;
  std::string description;
  std::function<void(CLI::App&)> add_options;
  std::function<int()> run;
};

template <typename Options>
Command MakeCommand(std::string group, std::string name, std::string description,
                    void (*add_options)(CLI::App&, Options&), int (*run)(const Options&)) {
  auto options = std::make_shared<Options>();
  return {std::move(group), std::move(name), std::move(description),
          [options, add_options](CLI::App& app) { add_options(app, *options); },
          [options, run] { return run(*options); }};
}

// The parent commands that only group others; each needs one of its subcommands.
struct CommandGroup {
  const char* name;
  const char* description;
};
const CommandGroup kGroups[] = {
    {"import", "Convert published recordings into a fitcal data set"},
    {"export", "Write a calibration for another tool"},
};

// The parent of a command of `group` ("" = the top level), added the first time it is asked for.
CLI::App* GroupOf(CLI::App& app, const std::string& group) {
  if (group.empty()) return &app;
  for (CLI::App* existing :
       app.get_subcommands([&](CLI::App* a) { return a->get_name() == group; }))
    return existing;
  for (const CommandGroup& g : kGroups) {
    if (group == g.name) {
      CLI::App* parent = app.add_subcommand(g.name, g.description);
      parent->require_subcommand(1);
      return parent;
    }
  }
  throw std::logic_error("fitcal: command group '" + group + "' is not in kGroups");
}

// Every subcommand of fitcal, in the order `fitcal --help` lists them. The first, fit, also runs
// when no subcommand is given.
std::vector<Command> Commands() {
  return {
      MakeCommand("", "fit",
                  "Fit, validate on held-out repetitions, write the calibrated YAML (default)",
                  &AddFitOptions, &RunFitCommand),
      MakeCommand("", "compare",
                  "Palacin Table 4 on your data: strategies x methods x {1, 5} repetitions",
                  &AddCompareOptions, &RunCompareCommand),
      MakeCommand("", "report",
                  "Validation report of a calibration: index.html, summary.md, metrics.csv/json",
                  &AddReportOptions, &RunReportCommand),
      MakeCommand("", "diagnose",
                  "Trace the residual of the model's fit to missing effects, any model "
                  "(docs/diagnose.md)",
                  &AddDiagnoseOptions, &RunDiagnoseCommand),
      MakeCommand("", "generalise",
                  "Train on one path type / session, test on the others (docs/optiodom.md)",
                  &AddGeneraliseOptions, &RunGeneraliseCommand),
      MakeCommand("", "simulate",
                  "Write a simulated data set: omni3 flower, or --model's trajectories "
                  "(docs/simulate.md)",
                  &AddSimulateOptions, &RunSimulateCommand),
      MakeCommand("import", "optiodom",
                  "OptiOdom sessions of one robot: omni3, omni4, diff or tricyc (Sousa et al. "
                  "2022)",
                  &AddImportOptiOdomOptions, &RunImportOptiOdomCommand),
      MakeCommand("import", "rosbag2",
                  "A ROS 2 bag (sqlite3 or MCAP, split or not): JointState + ground truth",
                  &AddImportRosbag2Options, &RunImportRosbag2Command),
      MakeCommand("export", "ros2-control",
                  "The parameter YAML of a ros2_controllers drive controller",
                  &AddExportRos2ControlOptions, &RunExportRos2ControlCommand),
      MakeCommand("", "fleet",
                  "Calibrations across robots and dates: a table per robot, outliers and trends",
                  &AddFleetOptions, &RunFleetCommand),
      MakeCommand("", "paper-tables",
                  "A paper's tables reproduced in simulation by --model (docs/asoc.md)",
                  &AddPaperTablesOptions, &RunPaperTablesCommand),
  };
}

// fitcal's --help. CLI11 2.1 writes an option's exclusions as " Excludes: --x" after its name,
// which overruns the name column and glues onto the description; here the description says it
// ("not with --x") and the parser still refuses both (exit 2). Every help ends with the command's
// own footer (fleet's columns), then the one list of exit statuses - once, whatever footer a
// subcommand inherited from its parent.
class HelpFormatter : public CLI::Formatter {
 public:
  // CLI11's make_option_opts without its "Needs:" and "Excludes:" lists.
  std::string make_option_opts(const CLI::Option* opt) const override {
    if (!opt->get_option_text().empty()) return " " + opt->get_option_text();
    std::ostringstream out;
    if (opt->get_type_size() != 0) {
      if (!opt->get_type_name().empty()) out << " " << get_label(opt->get_type_name());
      if (!opt->get_default_str().empty()) out << "=" << opt->get_default_str();
      if (opt->get_expected_max() == CLI::detail::expected_max_vector_size) {
        out << " ...";
      } else if (opt->get_expected_min() > 1) {
        out << " x " << opt->get_expected();
      }
      if (opt->get_required()) out << " " << get_label("REQUIRED");
    }
    if (!opt->get_envname().empty()) {
      out << " (" << get_label("Env") << ":" << opt->get_envname() << ")";
    }
    return out.str();
  }

  std::string make_option_desc(const CLI::Option* opt) const override {
    std::string description = opt->get_description();
    for (const CLI::Option* other : opt->get_excludes()) {
      description += " (not with " + other->get_name() + ")";
    }
    return description;
  }

  std::string make_footer(const CLI::App* app) const override {
    const std::string own = app->get_footer();
    return (own.empty() ? "" : own + "\n\n") + fitcal::kExitStatusHelp + "\n";
  }
};

// For an argument CLI11 did not expect: a directory given without its flag (`fitcal fit DIR`)
// is a data set meant for --logs; "" for anything else.
std::string UnexpectedArgumentHint(const CLI::ParseError& e) {
  if (dynamic_cast<const CLI::ExtrasError*>(&e) == nullptr) return "";
  const std::string what = e.what();
  const std::size_t colon = what.rfind(": ");
  std::istringstream arguments(colon == std::string::npos ? "" : what.substr(colon + 2));
  std::string argument;
  std::error_code ec;
  while (arguments >> argument) {
    if (std::filesystem::is_directory(argument, ec)) {
      return "; a data set directory is given as --logs " + argument;
    }
  }
  return "";
}

// The first of fit's flags given on the top level (`fitcal --train-reps 1-3 generalise`): bound
// to fit's options, another subcommand never read it, and the command ran without it, exit 0.
std::string TopLevelFitFlagGiven(const CLI::App& app) {
  for (const CLI::Option* option : app.get_options()) {
    const std::string name = option->get_name();
    if (option->count() > 0 && name != "--help" && name != "--version") return name;
  }
  return "";
}

// Usage errors exit 2 in one line, as the README says; CLI11's own codes (105 for a validation,
// 106 for a missing option, ...) and its second "Run with --help" line would say otherwise.
// Help and version requests keep CLI11's output and exit 0. Returns -1 when parsing succeeded.
int ParseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "fitcal: " << fitcal::io::OneLine(e.what(), 300) << UnexpectedArgumentHint(e)
              << " (see fitcal --help)\n";
    return 2;
  }
  return -1;
}

// Ceres logs through glog, which writes WARNING and above to stderr before InitGoogleLogging:
// lines such as "W... Ceres was compiled without ..." would break fitcal's one line per problem.
// What Ceres reports (termination, failure) reaches fitcal through its Summary instead.
void SilenceLibraryLogging(const char* argv0) {
  FLAGS_logtostderr = false;
  FLAGS_alsologtostderr = false;
  FLAGS_stderrthreshold = google::GLOG_FATAL;
  FLAGS_minloglevel = google::GLOG_FATAL;
  google::InitGoogleLogging(argv0);
  // For refusal_test: a library line at every severity below FATAL, as Ceres writes them on an
  // ill-posed problem (e.g. "W... residual_block.cc:129] Error in evaluating the ResidualBlock").
  if (std::getenv("FITCAL_TEST_LIBRARY_LOG") != nullptr) {
    LOG(INFO) << "test info line";
    LOG(WARNING) << "test warning line";
    LOG(ERROR) << "test error line";
  }
}

}  // namespace command_line

int RunCommandLine(int argc, char** argv) {
  using namespace command_line;
  fitcal::KeepFreedMemoryForReuse();  // odometry/memory_reuse.h says why
  SilenceLibraryLogging(argv[0]);
  // Ctrl-C or a scheduler's SIGTERM while an output is being written leaves no temporary behind.
  fitcal::io::RemoveTemporaryFilesOnSignals();
  // A file-size limit (ulimit -f) makes write() fail with EFBIG instead of killing fitcal: the
  // writer then removes its temporary file and says so in one line (io/atomic_file.h).
  signal(SIGXFSZ, SIG_IGN);
  // Nothing written may replace, hold or sit inside what the command reads (io/input_registry.h).
  fitcal::io::EnableInputGuard();
  CLI::App app{"fitcal " + std::string(fitcal::kVersion) +
               ": calibrate the kinematic parameters of a wheeled robot's odometry from encoder "
               "logs and ground truth"};
  app.set_version_flag("--version", std::string(fitcal::kVersion));
  app.require_subcommand(0, 1);
  // Before any subcommand is added: each takes its parent's formatter when it is created.
  app.formatter(std::make_shared<HelpFormatter>());

  const std::vector<Command> commands = Commands();
  // fit's flags on the top level too, bound to the same options: `fitcal --logs DIR` fits.
  commands.front().add_options(app);
  std::vector<CLI::App*> parsers;
  for (const Command& command : commands) {
    CLI::App* cmd = GroupOf(app, command.group)->add_subcommand(command.name, command.description);
    command.add_options(*cmd);
    parsers.push_back(cmd);
  }

  AddCommonValidators(app);
  if (const int usage_rc = ParseCommandLine(app, argc, argv); usage_rc >= 0) return usage_rc;
  for (std::size_t i = 0; i < commands.size(); ++i) {
    if (!parsers[i]->parsed()) continue;
    if (i > 0) {
      if (const std::string flag = TopLevelFitFlagGiven(app); !flag.empty()) {
        const std::string name =
            (commands[i].group.empty() ? "" : commands[i].group + " ") + commands[i].name;
        std::cerr << "fitcal: " << flag << " is given before '" << name
                  << "': there it is fit's flag, which '" << name
                  << "' does not read; write it after '" << name << "' (see fitcal --help)\n";
        return 2;
      }
    }
    return commands[i].run();
  }
  return commands.front().run();
}

}  // namespace fitcal::tools
