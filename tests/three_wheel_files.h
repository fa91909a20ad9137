#pragma once
// The shipped flower's file layout read and written whatever the robot YAML says: three wheel
// channels a, b, c (`t,w_a,w_b,w_c` or `t,ticks_a,...` with the robot YAML's `encoder:` block).
// A shortcut for tests and benchmarks on such files; every command reads a data set with its
// robot's own channels (io::LoadDataset(index, robot), through the model registry).

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "io/dataset.h"
#include "io/input_error.h"
#include "io/log_files.h"
#include "io/robot_yaml_blocks.h"
#include "io/yaml_reader.h"

namespace fitcal::io {

// The `model:` of a robot YAML; throws for a file that is not a robot YAML.
inline std::string ReadRobotModel(const std::string& path) {
  const YAML::Node root = LoadYamlFile(path);
  ExpectYamlType(root, YAML::NodeType::Map, path, "robot file");
  if (!root["model"])
    throw InputError(InputErrorKind::kMissingKey, path, 1, "robot has no 'model'");
  return YamlString(root["model"], path, "robot.model");
}

// The optional `encoder: {ticks_per_rev: N, cumulative: false}` block of any robot YAML; nullopt
// when absent; InputError when malformed.
inline std::optional<EncoderTicks> ReadEncoderTicks(const std::string& path) {
  const YAML::Node root = LoadYamlFile(path);
  ExpectYamlType(root, YAML::NodeType::Map, path, "robot file");
  return ReadEncoderTicksNode(root["encoder"], path);
}

inline Robot LegacyThreeWheelRobot(const std::optional<EncoderTicks>& ticks) {
  Robot robot;
  for (const char* w : {"a", "b", "c"}) {
    robot.channels.push_back(
        {w, ChannelKind::kWheelRate, std::string("w_") + w, std::string("ticks_") + w});
  }
  robot.encoder = ticks;
  return robot;
}

inline EncoderLog ReadEncoderCsv(const std::string& path,
                                 const std::optional<EncoderTicks>& ticks = std::nullopt) {
  return ReadEncoderCsv(path, LegacyThreeWheelRobot(ticks));
}

// Every run of a data set as three wheel columns; InputError naming the file and line.
inline Dataset LoadDataset(const DatasetIndex& index, const DatasetOptions& options = {}) {
  return LoadDataset(index, LegacyThreeWheelRobot(ReadEncoderTicks(index.robot_path)), options);
}

inline Dataset LoadDataset(const std::string& directory, const DatasetOptions& options = {}) {
  return LoadDataset(ReadDatasetIndex(directory, options), options);
}

// `t,w_a,w_b,w_c` as a recorder writes it (times %.6f, rates %.9g; row 0 at rest).
inline std::string EncoderCsv(const EncoderLog& log) {
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

// Any robot: header `t,<rate column per channel>`, then one row per time with what the CSV
// holds per channel (rates over the interval ending at the row, angle readings at the row time;
// row 0 sets the start, its rates are ignored).
inline std::string EncoderCsv(const Robot& robot, const std::vector<double>& t_s,
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

}  // namespace fitcal::io
