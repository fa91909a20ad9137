#include "io/dataset.h"

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include "io/input_error.h"
#include "io/log_files.h"
#include "io/robot_yaml.h"
#include "io/yaml_reader.h"
#include "odometry/parallel_for.h"

namespace fitcal::io {

namespace fs = std::filesystem;

namespace {

int LineOf(const YAML::Node& node) { return node.Mark().line + 1; }

// Resolves a path from dataset.yaml against the data set directory, refusing absolute paths and
// '..' escapes unless allowed: a data set is a self-contained directory.
std::string ResolvePath(const std::string& directory, const std::string& relative,
                        const DatasetOptions& options, const std::string& yaml_path,
                        const YAML::Node& node) {
  const fs::path p(relative);
  if (!options.allow_paths_outside) {
    if (p.is_absolute()) {
      throw InputError(InputErrorKind::kBadPath, yaml_path, LineOf(node),
                       "path '" + relative +
                           "' is absolute; paths are relative to the data set "
                           "directory (--allow-outside-paths to permit)");
    }
    for (const auto& part : p) {
      if (part == "..") {
        throw InputError(InputErrorKind::kBadPath, yaml_path, LineOf(node),
                         "path '" + relative +
                             "' leaves the data set directory "
                             "(--allow-outside-paths to permit)");
      }
    }
  }
  return p.is_absolute() ? p.string() : (fs::path(directory) / p).string();
}

}  // namespace

DatasetIndex ReadDatasetIndex(const std::string& directory, const DatasetOptions& options) {
  DatasetIndex index;
  index.directory = directory;
  index.yaml_path = (fs::path(directory) / "dataset.yaml").string();
  const std::string& yaml_path = index.yaml_path;
  // error_code overloads: a path the OS refuses (too long, no permission) is bad input, not a
  // std::filesystem_error escaping the loader (found by tests/fuzz, dataset_yaml).
  std::error_code fs_error;
  if (!fs::is_directory(directory, fs_error)) {
    throw InputError(InputErrorKind::kMissingFile, directory, 0, "not a directory");
  }
  const YAML::Node root = LoadYamlFile(yaml_path);
  YamlMap top(root, yaml_path, "dataset");
  const YAML::Node robot_node = top.Required("robot");
  index.robot_path = ResolvePath(directory, YamlString(robot_node, yaml_path, "dataset.robot"),
                                 options, yaml_path, robot_node);
  if (!fs::exists(index.robot_path, fs_error)) {
    throw InputError(InputErrorKind::kMissingFile, yaml_path, LineOf(robot_node),
                     "robot file '" + index.robot_path + "' does not exist");
  }
  top.Optional("name");
  top.Optional("description");
  const YAML::Node runs = top.Required("runs");
  ExpectYamlType(runs, YAML::NodeType::Sequence, yaml_path, "dataset.runs");
  if (runs.size() == 0) {
    throw InputError(InputErrorKind::kTooFewSamples, yaml_path, LineOf(runs), "no runs listed");
  }
  top.RejectUnread();

  index.runs.resize(runs.size());
  std::set<std::string> ids;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const YAML::Node node = runs[i];
    YamlMap run(node, yaml_path, "run " + std::to_string(i + 1));
    DatasetIndexEntry& entry = index.runs[i];
    entry.id = run.String("id");
    if (!ids.insert(entry.id).second) {
      throw InputError(InputErrorKind::kDuplicateRunId, yaml_path, LineOf(node),
                       "run id '" + entry.id + "' is used twice");
    }
    entry.trajectory = run.String("trajectory");
    entry.repetition = run.Int("repetition");
    entry.encoders_path =
        ResolvePath(directory, run.String("encoders"), options, yaml_path, node["encoders"]);
    entry.ground_truth_path = ResolvePath(directory, run.String("ground_truth"), options, yaml_path,
                                          node["ground_truth"]);
    const YAML::Node start = run.Optional("start_pose");
    if (start) {
      ExpectYamlType(start, YAML::NodeType::Sequence, yaml_path, "start_pose");
      if (start.size() != 3) {
        throw InputError(InputErrorKind::kBadValue, yaml_path, LineOf(start),
                         "start_pose must be [x, y, theta] (m, m, rad)");
      }
      entry.start_pose = Pose2d{YamlDouble(start[0], yaml_path, "start_pose x"),
                                YamlDouble(start[1], yaml_path, "start_pose y"),
                                YamlDouble(start[2], yaml_path, "start_pose theta")};
    }
    run.RejectUnread();
  }
  return index;
}

void CheckGroundTruthOverlap(const GroundTruthTrack& ground_truth, double enc_begin_s,
                             double enc_end_s, const std::string& ground_truth_path) {
  const double gt_begin = ground_truth.t_s.front(), gt_end = ground_truth.t_s.back();
  if (gt_end <= enc_begin_s || gt_begin >= enc_end_s) {
    std::ostringstream msg;
    msg << "ground truth [" << gt_begin << ", " << gt_end << "] s does not overlap the encoder "
        << "span [" << enc_begin_s << ", " << enc_end_s << "] s (different clocks or wrong file?)";
    throw InputError(InputErrorKind::kNoOverlap, ground_truth_path, 0, msg.str());
  }
}

Dataset LoadDataset(const std::string& directory, const DatasetOptions& options) {
  return LoadDataset(ReadDatasetIndex(directory, options), options);
}

Dataset LoadDataset(const DatasetIndex& index, const DatasetOptions& options) {
  // The commands that call this form (compare, report, diagnose, generalise) still serve omni3
  // robots only; say so rather than failing on the first encoder header.
  const std::string model = ReadRobotModel(index.robot_path);
  if (model != "omni3") {
    const int line = LoadYamlFile(index.robot_path)["model"].Mark().line + 1;
    throw InputError(InputErrorKind::kUnknownModel, index.robot_path, line,
                     "model '" + model +
                         "': this command serves omni3 robots only so far ('fitcal fit' serves "
                         "every model)");
  }
  return LoadDataset(index, LegacyThreeWheelRobot(ReadEncoderTicks(index.robot_path)), options);
}

Dataset LoadDataset(const DatasetIndex& index, const Robot& robot, const DatasetOptions& options) {
  Dataset dataset;
  dataset.directory = index.directory;
  dataset.robot_path = index.robot_path;
  dataset.runs.resize(index.runs.size());
  ParallelFor(index.runs.size(), options.num_threads, [&](std::size_t i) {
    const DatasetIndexEntry& entry = index.runs[i];
    RunLog& log = dataset.runs[i];
    log.id = entry.id;
    log.trajectory = entry.trajectory;
    log.repetition = entry.repetition;
    log.start_pose = entry.start_pose;
    log.encoders = ReadEncoderCsv(entry.encoders_path, robot);
    log.ground_truth = ReadGroundTruth(entry.ground_truth_path);
    CheckGroundTruthOverlap(log.ground_truth, log.encoders.t_s.front(), log.encoders.t_s.back(),
                            entry.ground_truth_path);
  });
  return dataset;
}

std::string DatasetYaml(const std::string& robot_path, const std::vector<DatasetEntry>& runs) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "robot" << YAML::Value << robot_path;
  out << YAML::Key << "runs" << YAML::Value << YAML::BeginSeq;
  for (const DatasetEntry& run : runs) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "id" << YAML::Value << run.id;
    out << YAML::Key << "trajectory" << YAML::Value << run.trajectory;
    out << YAML::Key << "repetition" << YAML::Value << run.repetition;
    out << YAML::Key << "encoders" << YAML::Value << run.encoders;
    out << YAML::Key << "ground_truth" << YAML::Value << run.ground_truth;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

std::string EncoderCsv(const EncoderLog& log) {
  std::string out = "t,w_a,w_b,w_c\n";
  out.reserve(log.t_s.size() * 40);
  char line[160];
  for (std::size_t k = 0; k < log.t_s.size(); ++k) {
    const double* w = k == 0 ? nullptr : log.samples[k - 1].value;
    const int n = w == nullptr ? std::snprintf(line, sizeof line, "%.6f,0,0,0\n", log.t_s[k])
                               : std::snprintf(line, sizeof line, "%.6f,%.9g,%.9g,%.9g\n",
                                               log.t_s[k], w[0], w[1], w[2]);
    out.append(line, static_cast<std::size_t>(n));
  }
  return out;
}

std::string EncoderCsv(const Robot& robot, const std::vector<double>& t_s,
                       const std::vector<std::vector<double>>& rows) {
  std::string out = "t";
  for (const ChannelInfo& c : robot.channels) out += "," + c.rate_column;
  out += "\n";
  char field[64];
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    out.append(field, static_cast<std::size_t>(std::snprintf(field, sizeof field, "%.6f", t_s[k])));
    for (double v : rows[k]) {
      out.append(field, static_cast<std::size_t>(std::snprintf(field, sizeof field, ",%.9g", v)));
    }
    out += "\n";
  }
  return out;
}

std::string GroundTruthCsv(const GroundTruthTrack& track) {
  std::string out = "t,x,y,theta\n";
  char line[160];
  for (std::size_t k = 0; k < track.t_s.size(); ++k) {
    const Pose2d& p = track.world_T_robot[k];
    const int n =
        std::snprintf(line, sizeof line, "%.6f,%.6f,%.6f,%.7f\n", track.t_s[k], p.x, p.y, p.theta);
    out.append(line, static_cast<std::size_t>(n));
  }
  return out;
}

}  // namespace fitcal::io
