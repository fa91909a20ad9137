#include "io/robot_yaml.h"

#include <yaml-cpp/yaml.h>

#include "io/input_error.h"
#include "io/robot_yaml_blocks.h"
#include "io/yaml_reader.h"

namespace fitcal::io {

std::optional<EncoderTicks> ReadEncoderTicks(const std::string& path) {
  const YAML::Node root = LoadYamlFile(path);
  ExpectYamlType(root, YAML::NodeType::Map, path, "robot file");
  return ReadEncoderTicksNode(root["encoder"], path);
}

std::string ReadRobotModel(const std::string& path) {
  const YAML::Node root = LoadYamlFile(path);
  ExpectYamlType(root, YAML::NodeType::Map, path, "robot file");
  if (!root["model"])
    throw InputError(InputErrorKind::kMissingKey, path, 1, "robot has no 'model'");
  return YamlString(root["model"], path, "robot.model");
}

}  // namespace fitcal::io
