#include "io/calibration_yaml.h"

#include <algorithm>
#include <cmath>

#include "io/input_error.h"
#include "io/yaml_reader.h"
#include "odometry/aligned_run.h"

namespace fitcal::io {

namespace {

// The bound of the track fit's clock offsets (kMaxClockOffsetS): a recorded offset beyond it was
// not written by fit. The last digit of a written value may round past it.
constexpr double kMaxRecordedClockOffsetS = kMaxClockOffsetS + 1e-9;

// The block of a parsed file, or a null node for a plain robot YAML.
YAML::Node CalibrationNode(const YAML::Node& root, const std::string& path) {
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

// A correlation matrix is symmetric; its two halves are written from one number each, to 4
// significant digits, so they differ by at most a rounding of the last one.
void RequireSymmetric(const std::vector<std::vector<double>>& c, const YAML::Node& node,
                      const std::string& path) {
  constexpr double kWrittenDigitsTolerance = 1e-3;
  for (std::size_t r = 0; r < c.size(); ++r) {
    for (std::size_t k = 0; k < r; ++k) {
      if (std::abs(c[r][k] - c[k][r]) <= kWrittenDigitsTolerance) continue;
      throw InputError(InputErrorKind::kBadValue, path, node[r].Mark().line + 1,
                       "calibration.correlation: row " + std::to_string(r + 1) + ", column " +
                           std::to_string(k + 1) + " is not the same as row " +
                           std::to_string(k + 1) + ", column " + std::to_string(r + 1) +
                           " (a correlation matrix is symmetric)");
    }
  }
}

// `sigma: {name_unit: value, ...}` and `correlation: [[...], ...]`, square and of the same size,
// or nothing at all when the fit recorded no uncertainty.
void ReadUncertainty(const YAML::Node& block, const std::string& path, CalibrationProvenance* p) {
  const YAML::Node sigma = block["sigma"];
  if (!sigma || sigma.IsNull()) return;
  ExpectYamlType(sigma, YAML::NodeType::Map, path, "calibration.sigma");
  const auto add = [&](const std::string& key, const YAML::Node& node) {
    const double value = YamlDouble(node, path, "calibration.sigma." + key);
    if (!(value >= 0.0) || !std::isfinite(value)) {
      throw InputError(InputErrorKind::kBadValue, path, node.Mark().line + 1,
                       "calibration.sigma." + key + ": not a finite non-negative number");
    }
    p->sigma.emplace_back(key, value);
    p->sigma_lines.push_back(node.Mark().line + 1);
  };
  for (const auto& entry : sigma) {
    const std::string key = YamlString(entry.first, path, "calibration.sigma");
    if (!entry.second.IsSequence()) {
      add(key, entry.second);
      continue;
    }
    // omni3 files from before the model seam: one list per quantity (`distance_m: [a, b, c]`).
    for (std::size_t i = 0; i < entry.second.size(); ++i) {
      add(key + "[" + std::to_string(i) + "]", entry.second[i]);
    }
  }
  const YAML::Node correlation = block["correlation"];
  if (!correlation || correlation.IsNull()) return;
  ExpectYamlType(correlation, YAML::NodeType::Sequence, path, "calibration.correlation");
  for (const YAML::Node& row : correlation) {
    ExpectYamlType(row, YAML::NodeType::Sequence, path, "calibration.correlation");
    std::vector<double> values;
    for (const YAML::Node& item : row) {
      values.push_back(YamlDouble(item, path, "calibration.correlation"));
      // Written to 4 digits, so a correlation reads back within [-1, 1] exactly; anything else
      // was edited and would make the propagated variances negative.
      if (!(std::abs(values.back()) <= 1.0)) {
        throw InputError(InputErrorKind::kBadValue, path, item.Mark().line + 1,
                         "calibration.correlation: " + item.Scalar() +
                             " is not a correlation (between -1 and 1)");
      }
    }
    if (values.size() != p->sigma.size()) {
      throw InputError(InputErrorKind::kBadValue, path, row.Mark().line + 1,
                       "calibration.correlation: a row of " + std::to_string(values.size()) +
                           " values for " + std::to_string(p->sigma.size()) + " sigmas");
    }
    p->correlation.push_back(std::move(values));
  }
  if (p->correlation.size() != p->sigma.size()) {
    throw InputError(InputErrorKind::kBadValue, path, correlation.Mark().line + 1,
                     "calibration.correlation: " + std::to_string(p->correlation.size()) +
                         " rows for " + std::to_string(p->sigma.size()) + " sigmas");
  }
  RequireSymmetric(p->correlation, correlation, path);
}

// Every key a fitcal writer puts in the block (io/calibration_block.cc; omni3's
// inverse_kinematic_matrix, models/omni3/omni3_robot_model.cc, and the omni and mecanum robots'
// forward_kinematic_matrix, models/omni/omni_model_n.h; export's odometry_covariance,
// interchange/ros2/controller_export.cc). An edited block is read back by
// report, export and fleet: a key none of them wrote is a typo whose value would be ignored in
// silence (`at_bounds: [r_left]` would leave the bound unsaid), so it is refused at its line.
void RejectKeysNoWriterWrites(const YAML::Node& block, const std::string& path) {
  static const char* const kWritten[] = {
      "method", "objective", "dataset", "tool_version", "termination", "selected", "selected_on",
      "training_repetitions", "validation_repetitions", "training_runs", "validation_runs",
      "training_trajectories", "training_run_ids", "training_fingerprint", "cf_training",
      "cf_validation", "held", "tied", "at_bound", "not_determined", "sigma", "correlation",
      "clock_offsets", "inverse_kinematic_matrix", "forward_kinematic_matrix",
      "odometry_covariance"};
  YamlMap map(block, path, "calibration");
  for (const char* key : kWritten) (void)map.Optional(key);
  map.RejectUnread();
}

struct BeforeAfter {
  double before = 0.0;
  double after = 0.0;
};

// `<key>: {before: x, after: y}` (the CF before and after the calibration), when present.
std::optional<BeforeAfter> ReadBeforeAfter(const YAML::Node& block, const std::string& key,
                                           const std::string& path) {
  const YAML::Node node = block[key];
  if (!node || node.IsNull()) return std::nullopt;
  YamlMap map(node, path, "calibration." + key);
  const BeforeAfter out{map.Double("before"), map.Double("after")};
  map.RejectUnread();
  return out;
}

// calibration.clock_offsets, when present.
void ReadClockOffsets(const YAML::Node& block, const std::string& path, CalibrationProvenance* p) {
  const YAML::Node node = block["clock_offsets"];
  if (!node || node.IsNull()) return;
  ExpectYamlType(node, YAML::NodeType::Map, path, "calibration.clock_offsets");
  YamlMap offsets(node, path, "calibration.clock_offsets");
  (void)offsets.Optional("meaning");  // the writer's explanation for a reader, not data
  const YAML::Node grouping = offsets.Optional("grouping");
  if (grouping && !grouping.IsNull()) {
    p->clock_offset_grouping = YamlString(grouping, path, "calibration.clock_offsets.grouping");
  }
  const YAML::Node groups = offsets.Optional("groups");
  offsets.RejectUnread();
  if (!groups) return;
  ExpectYamlType(groups, YAML::NodeType::Sequence, path, "calibration.clock_offsets.groups");
  for (const YAML::Node& g : groups) {
    YamlMap entry(g, path, "calibration.clock_offsets.groups");
    CalibrationProvenance::ClockOffset c;
    c.group = entry.String("group");
    c.offset_s = entry.Double("offset_s");
    c.sigma_s = entry.Double("sigma_s");
    entry.RejectUnread();
    if (!std::isfinite(c.offset_s) || !std::isfinite(c.sigma_s) || c.sigma_s < 0.0) {
      throw InputError(InputErrorKind::kBadValue, path, g.Mark().line + 1,
                       "calibration.clock_offsets: offset_s and sigma_s must be finite, sigma_s "
                       ">= 0");
    }
    const int line = g.Mark().line + 1;
    for (const CalibrationProvenance::ClockOffset& earlier : p->clock_offsets) {
      if (earlier.group == c.group) {
        throw InputError(InputErrorKind::kBadValue, path, line,
                         "calibration.clock_offsets: group '" + c.group +
                             "' is listed twice (which offset applies?)");
      }
    }
    if (std::abs(c.offset_s) > kMaxRecordedClockOffsetS) {
      throw InputError(InputErrorKind::kBadValue, path, line,
                       "calibration.clock_offsets: group '" + c.group + "' offset " +
                           std::to_string(c.offset_s) + " s is beyond the fit's bound of " +
                           std::to_string(kMaxRecordedClockOffsetS) +
                           " s (an edited file? fit never writes one)");
    }
    p->clock_offsets.push_back(c);
  }
}

std::vector<int> TrainingRepetitions(const YAML::Node& block, const std::string& path) {
  const YAML::Node reps = block["training_repetitions"];
  if (!reps) {
    throw InputError(InputErrorKind::kMissingKey, path, block.Mark().line + 1,
                     "calibration: missing key 'training_repetitions'");
  }
  return Repetitions(reps, path);
}

}  // namespace

std::optional<CalibrationProvenance> ReadCalibrationProvenance(const std::string& path) {
  return ReadCalibrationProvenance(LoadYamlFile(path), path);
}

std::optional<CalibrationProvenance> ReadCalibrationProvenance(const YAML::Node& root,
                                                               const std::string& path) {
  const YAML::Node block = CalibrationNode(root, path);
  if (!block || block.IsNull()) return std::nullopt;
  RejectKeysNoWriterWrites(block, path);
  CalibrationProvenance p;
  p.path = path;
  p.training_repetitions = TrainingRepetitions(block, path);
  p.method = OptionalString(block, "method", path);
  p.dataset = OptionalString(block, "dataset", path);
  p.termination = OptionalString(block, "termination", path);
  p.training_trajectories = OptionalString(block, "training_trajectories", path);
  p.training_fingerprint = OptionalString(block, "training_fingerprint", path);
  p.training_run_ids = Strings(block["training_run_ids"], path, "calibration.training_run_ids");
  p.at_bound = Strings(block["at_bound"], path, "calibration.at_bound");
  if (const std::optional<BeforeAfter> cf = ReadBeforeAfter(block, "cf_training", path)) {
    p.cf_training_before = cf->before;
    p.cf_training_after = cf->after;
    p.has_training_cf = true;
  }
  // Read for its check only: a hand-edited block is validated whole, not just what is used.
  (void)ReadBeforeAfter(block, "cf_validation", path);
  ReadUncertainty(block, path, &p);
  ReadClockOffsets(block, path, &p);
  return p;
}

namespace {

bool RecordedKeyMatches(const std::string& key, const ParameterInfo& info) {
  if (key == info.KeyName()) return true;
  const std::string unit = info.KeyName().substr(info.name.size());
  if (unit.empty()) return false;  // a ratio's key is its name alone
  const std::size_t bracket = key.find('[');
  if (bracket == std::string::npos || bracket < unit.size()) return false;
  return key.compare(bracket - unit.size(), unit.size(), unit) == 0;
}

}  // namespace

std::vector<double> RecordedSigmas(const CalibrationProvenance& provenance,
                                   const std::vector<ParameterInfo>& parameters) {
  const auto& recorded = provenance.sigma;
  for (std::size_t r = 0; r < recorded.size(); ++r) {
    if (std::any_of(parameters.begin(), parameters.end(), [&](const ParameterInfo& info) {
          return RecordedKeyMatches(recorded[r].first, info);
        })) {
      continue;
    }
    std::string keys;
    for (const ParameterInfo& info : parameters)
      keys += (keys.empty() ? "" : ", ") + info.KeyName();
    throw InputError(InputErrorKind::kUnknownKey, provenance.path,
                     r < provenance.sigma_lines.size() ? provenance.sigma_lines[r] : 0,
                     "calibration.sigma: '" + recorded[r].first +
                         "' names no parameter of this robot (its keys: " + keys + ")");
  }
  if (recorded.size() != parameters.size()) return {};
  std::vector<double> sigma(parameters.size());
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    if (!RecordedKeyMatches(recorded[k].first, parameters[k])) return {};
    sigma[k] = recorded[k].second / parameters[k].DisplayScale();
  }
  return sigma;
}

}  // namespace fitcal::io
