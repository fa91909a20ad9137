#pragma once
// A data set directory: dataset.yaml naming the robot and the runs, and one encoder CSV and one
// ground-truth file per run (docs/data_format.md). Loading checks everything a fit relies on.

#include <string>
#include <vector>

#include "odometry/run_log.h"

namespace fitcal::io {

struct DatasetOptions {
  // Paths in dataset.yaml must stay inside the data set directory unless this is set.
  bool allow_paths_outside = false;
  // Loader threads (0 = all cores).
  int num_threads = 0;
};

struct Dataset {
  std::string directory;
  std::string robot_path;  // resolved path of the robot YAML
  std::vector<RunLog> runs;
};

// Loads dataset.yaml and every run it lists; throws InputError naming the file and line.
Dataset LoadDataset(const std::string& directory, const DatasetOptions& options = {});

// One run as dataset.yaml lists it; used by writers (the simulator, importers).
struct DatasetEntry {
  std::string id;
  std::string trajectory;
  int repetition = 0;
  std::string encoders;      // relative to the directory
  std::string ground_truth;  // relative to the directory
};

std::string DatasetYaml(const std::string& robot_path, const std::vector<DatasetEntry>& runs);
std::string EncoderCsv(const EncoderLog& log);
std::string GroundTruthCsv(const GroundTruthTrack& track);

}  // namespace fitcal::io
