#pragma once
// What every command that reads a data set shares: the options that say where and how to read it
// (`--logs`, `--threads`, `--allow-outside-paths`, declared once), and the load-and-check step
// (dataset.yaml read and its paths checked, the runs loaded, any problem turned into one line and
// a non-zero exit at the tool's edge).

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "io/dataset.h"

namespace fitcal {
struct Robot;
}

namespace fitcal::tools {

struct DatasetCommandOptions {
  std::string logs;                  // the data set directory (holds dataset.yaml)
  int threads = 0;                   // worker threads, also the loader's (0 = all cores)
  bool allow_outside_paths = false;  // dataset.yaml paths may be absolute or leave the directory

  io::DatasetOptions Loading() const;
};

// Declares --logs, --threads and --allow-outside-paths on `app`, bound to `options`. `fit` is
// also the command without a name (`fitcal --logs DIR`), so its --logs is checked when it runs
// rather than by the parser.
enum class LogsFlag { kRequired, kCheckedByCommand };
void AddDatasetOptions(CLI::App& app, DatasetCommandOptions& options,
                       LogsFlag logs = LogsFlag::kRequired);

// The data set's index (dataset.yaml parsed, every path resolved and checked; no log read yet),
// and the files a run of the command reads (an output must not replace one).
struct OpenedDataset {
  io::DatasetIndex index;
  std::vector<std::string> inputs;
};
OpenedDataset OpenDataset(const DatasetCommandOptions& options);

// Every run of the data set, read with the robot's own channels (the one loader of every command).
io::Dataset LoadRuns(const DatasetCommandOptions& options, const io::DatasetIndex& index,
                     const Robot& robot);

// A refusal: `fitcal: <why>` on one line of stderr; returns the usage exit status 2.
int Refuse(const std::string& why);

// The tool's edge: runs `command` and turns an exception (io::InputError carries file:line in
// what()) into `<prefix>: <what>` on one line of stderr and exit status 1, or the status a
// CommandFailure (io/command_failure.h) carries.
int RunReportingErrors(const std::string& prefix, const std::function<int()>& command);

}  // namespace fitcal::tools
