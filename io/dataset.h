#pragma once
// A data set directory: dataset.yaml naming the robot and the runs, and one encoder CSV and one
// ground-truth file per run (README.md, "Data set format"). Loading checks everything a fit relies
// on.

#include <optional>
#include <string>
#include <vector>

#include "odometry/robot.h"
#include "odometry/run_log.h"

namespace fitcal::io {

struct DatasetOptions {
  // Paths in dataset.yaml must stay inside the data set directory unless this is set.
  bool allow_paths_outside = false;
  // Loader threads (0 = all cores).
  int num_threads = 0;
};

// dataset.yaml alone, paths resolved and checked; the log files are not read yet. Models whose
// encoder files differ from omni3's (e.g. ASOC) load their logs from this index.
struct DatasetIndexEntry {
  std::string id;
  std::string trajectory;
  int repetition = 0;
  std::string encoders_path;
  std::string ground_truth_path;
  std::optional<Pose2d> start_pose;
};

struct DatasetIndex {
  std::string directory;
  std::string yaml_path;
  std::string robot_path;  // resolved path of the robot YAML
  std::vector<DatasetIndexEntry> runs;
};

DatasetIndex ReadDatasetIndex(const std::string& directory, const DatasetOptions& options = {});

struct Dataset {
  std::string directory;
  std::string robot_path;  // resolved path of the robot YAML
  std::vector<RunLog> runs;
};

// Every run's encoder CSV read with the robot's channels (log_files.h); every command reads a data
// set so, the robot from the model registry (io, below it, names no model). Throws InputError
// naming the file and line.
Dataset LoadDataset(const DatasetIndex& index, const Robot& robot,
                    const DatasetOptions& options = {});

// A writer's staged data set read back as every command reads it, so that what a writer makes is
// what `fit` accepts; a refusal (InputError) names the file as it will be under `out`.
void ReadBackStagedDataset(const std::string& staged_dir, const std::string& out,
                           const Robot& robot);

// One run as dataset.yaml lists it; used by writers (the simulator, importers).
struct DatasetEntry {
  std::string id;
  std::string trajectory;
  int repetition = 0;
  std::string encoders;      // relative to the directory
  std::string ground_truth;  // relative to the directory
};

std::string DatasetYaml(const std::string& robot_path, const std::vector<DatasetEntry>& runs);
std::string GroundTruthCsv(const GroundTruthTrack& track);

// Appends v as printf("%.<precision>f") / printf("%.<precision>g") would write it, byte for byte,
// without printf's per-call parsing and locale work (std::to_chars, ~5x faster per value).
void AppendFixed(std::string* out, double v, int precision);
void AppendGeneral(std::string* out, double v, int precision);

}  // namespace fitcal::io
