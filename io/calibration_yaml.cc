#include "io/calibration_yaml.h"

#include <cmath>

#include "io/input_error.h"
#include "io/yaml_reader.h"

namespace fitcal::io {

namespace {

// The block, or a null node for a plain robot YAML.
YAML::Node CalibrationNode(const std::string& path) {
  const YAML::Node root = LoadYamlFile(path);
  ExpectYamlType(root, YAML::NodeType::Map, path, "robot");
  const YAML::Node block = root["calibration"];
  if (!block || block.IsNull()) return YAML::Node();
  ExpectYamlType(block, YAML::NodeType::Map, path, "calibration");
  return block;
}

std::vector<int> Repetitions(const YAML::Node& reps, const std::string& path) {
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

std::vector<std::string> Strings(const YAML::Node& list, const std::string& path,
                                 const std::string& what) {
  std::vector<std::string> out;
  if (!list || list.IsNull()) return out;
  ExpectYamlType(list, YAML::NodeType::Sequence, path, what);
  for (const YAML::Node& item : list) out.push_back(YamlString(item, path, what));
  return out;
}

std::string OptionalString(const YAML::Node& block, const char* key, const std::string& path) {
  const YAML::Node node = block[key];
  if (!node || node.IsNull()) return "";
  return YamlString(node, path, std::string("calibration.") + key);
}

}  // namespace

std::optional<std::vector<int>> ReadCalibrationTrainingRepetitions(const std::string& path) {
  const YAML::Node block = CalibrationNode(path);
  if (!block || block.IsNull()) return std::nullopt;
  const YAML::Node reps = block["training_repetitions"];
  if (!reps) {
    throw InputError(InputErrorKind::kMissingKey, path, block.Mark().line + 1,
                     "calibration: missing key 'training_repetitions'");
  }
  return Repetitions(reps, path);
}

std::optional<CalibrationProvenance> ReadCalibrationProvenance(const std::string& path) {
  const YAML::Node block = CalibrationNode(path);
  if (!block || block.IsNull()) return std::nullopt;
  CalibrationProvenance p;
  if (const std::optional<std::vector<int>> reps = ReadCalibrationTrainingRepetitions(path)) {
    p.training_repetitions = *reps;
  }
  p.method = OptionalString(block, "method", path);
  p.dataset = OptionalString(block, "dataset", path);
  p.termination = OptionalString(block, "termination", path);
  p.training_trajectories = OptionalString(block, "training_trajectories", path);
  p.training_fingerprint = OptionalString(block, "training_fingerprint", path);
  p.training_run_ids = Strings(block["training_run_ids"], path, "calibration.training_run_ids");
  p.at_bound = Strings(block["at_bound"], path, "calibration.at_bound");
  const YAML::Node cf = block["cf_training"];
  if (cf && !cf.IsNull()) {
    ExpectYamlType(cf, YAML::NodeType::Map, path, "calibration.cf_training");
    p.cf_training_before = YamlDouble(cf["before"], path, "calibration.cf_training.before");
    p.cf_training_after = YamlDouble(cf["after"], path, "calibration.cf_training.after");
    p.has_training_cf = true;
  }
  return p;
}

}  // namespace fitcal::io
