#include "io/calibration_yaml.h"

#include <cmath>

#include "io/input_error.h"
#include "io/yaml_reader.h"

namespace fitcal::io {

std::optional<std::vector<int>> ReadCalibrationTrainingRepetitions(const std::string& path) {
  const YAML::Node root = LoadYamlFile(path);
  ExpectYamlType(root, YAML::NodeType::Map, path, "robot");
  const YAML::Node block = root["calibration"];
  if (!block || block.IsNull()) return std::nullopt;
  ExpectYamlType(block, YAML::NodeType::Map, path, "calibration");
  const YAML::Node reps = block["training_repetitions"];
  if (!reps) {
    throw InputError(InputErrorKind::kMissingKey, path, block.Mark().line + 1,
                     "calibration: missing key 'training_repetitions'");
  }
  ExpectYamlType(reps, YAML::NodeType::Sequence, path, "calibration.training_repetitions");
  std::vector<int> out;
  for (const YAML::Node& item : reps) {
    const double v = YamlDouble(item, path, "calibration.training_repetitions");
    if (v != std::floor(v) || v < 0 || v > 1e6) {
      throw InputError(InputErrorKind::kBadValue, path, item.Mark().line + 1,
                       "calibration.training_repetitions: not a repetition number");
    }
    out.push_back(static_cast<int>(v));
  }
  return out;
}

}  // namespace fitcal::io
