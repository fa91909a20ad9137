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

// Throws kNoOverlap when the ground truth does not share time with [enc_begin_s, enc_end_s].
void CheckGroundTruthOverlap(const GroundTruthTrack& ground_truth, double enc_begin_s,
                             double enc_end_s, const std::string& ground_truth_path);

struct Dataset {
  std::string directory;
  std::string robot_path;  // resolved path of the robot YAML
  std::vector<RunLog> runs;
};

// Loads dataset.yaml and every run it lists as three wheel columns w_a, w_b, w_c (the shipped
// flower's layout), whatever the robot YAML says: a shortcut for tests and benchmarks on such
// files. Every command reads a data set with its robot's own channels (the overload below, through
// the model registry: io, below it, names no model). Throws InputError naming the file and line.
Dataset LoadDataset(const std::string& directory, const DatasetOptions& options = {});
// The same from an index already read (dataset.yaml is then parsed once).
Dataset LoadDataset(const DatasetIndex& index, const DatasetOptions& options = {});
// Any robot model: every run's encoder CSV read with the robot's channels (log_files.h).
Dataset LoadDataset(const DatasetIndex& index, const Robot& robot,
                    const DatasetOptions& options = {});

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
// Any robot: header `t,<rate column per channel>`, then one row per time with what the CSV
// holds per channel (rates over the interval ending at the row, angle readings at the row time;
// row 0 sets the start, its rates are ignored).
std::string EncoderCsv(const Robot& robot, const std::vector<double>& t_s,
                       const std::vector<std::vector<double>>& rows);
std::string GroundTruthCsv(const GroundTruthTrack& track);

// Appends v as printf("%.<precision>f") / printf("%.<precision>g") would write it, byte for byte,
// without printf's per-call parsing and locale work (std::to_chars, ~5x faster per value).
void AppendFixed(std::string* out, double v, int precision);
void AppendGeneral(std::string* out, double v, int precision);

}  // namespace fitcal::io
