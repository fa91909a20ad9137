#include "cli/dataset_command.h"

#include <exception>
#include <iostream>

#include "io/input_error.h"
#include "odometry/robot.h"
#include "io/command_failure.h"
#include "io/output_guard.h"

namespace fitcal::tools {

io::DatasetOptions DatasetCommandOptions::Loading() const {
  io::DatasetOptions loading;
  loading.allow_paths_outside = allow_outside_paths;
  loading.num_threads = threads;
  return loading;
}

void AddDatasetOptions(CLI::App& app, DatasetCommandOptions& options, LogsFlag logs) {
  CLI::Option* logs_option =
      app.add_option("--logs", options.logs, "Data set directory (holds dataset.yaml)")
          ->check(CLI::ExistingDirectory);
  if (logs == LogsFlag::kRequired) logs_option->required();
  app.add_option("--threads", options.threads, "Worker threads (0 = all cores)")
      ->capture_default_str();
  app.add_flag("--allow-outside-paths", options.allow_outside_paths,
               "Allow dataset.yaml paths that are absolute or leave the data set directory");
}

OpenedDataset OpenDataset(const DatasetCommandOptions& options) {
  OpenedDataset opened;
  opened.index = io::ReadDatasetIndex(options.logs, options.Loading());
  opened.inputs = io::DatasetInputs(opened.index);
  return opened;
}

io::Dataset LoadRuns(const DatasetCommandOptions& options, const io::DatasetIndex& index,
                     const Robot& robot) {
  return io::LoadDataset(index, robot, options.Loading());
}

int Refuse(const std::string& why) {
  std::cerr << "fitcal: " << why << "\n";
  return 2;
}

int RunReportingErrors(const std::string& prefix, const std::function<int()>& command) {
  try {
    return command();
  } catch (const CommandFailure& e) {
    std::cerr << prefix << ": " << io::OneLine(e.what(), 500) << "\n";
    return e.exit_status();
  } catch (const std::exception& e) {
    std::cerr << prefix << ": " << io::OneLine(e.what(), 500) << "\n";
    return 1;
  }
}

}  // namespace fitcal::tools
