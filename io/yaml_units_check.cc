#include "io/yaml_units_check.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "io/input_error.h"
#include "io/text_file.h"
#include "io/yaml_reader.h"
#include "odometry/text_format.h"

namespace fitcal::io {
namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The numbers of a scalar or a list of scalars (a bounds pair); non-numbers are skipped (their
// own reader names them).
std::vector<std::pair<double, int>> Numbers(const YAML::Node& node) {
  std::vector<std::pair<double, int>> out;
  auto add = [&](const YAML::Node& n) {
    double v = 0.0;
    bool finite = false;
    if (n.IsScalar() && ParseDouble(n.Scalar(), &v, &finite) && finite) {
      out.emplace_back(v, LineOf(n));
    }
  };
  if (node.IsScalar()) add(node);
  if (node.IsSequence()) {
    for (const YAML::Node& child : node) add(child);
  }
  return out;
}

std::string Text(double v) { return StrFormat("%g", v); }

void CheckLengths(const std::string& key, const YAML::Node& value, const std::string& path) {
  for (const auto& [v, line] : Numbers(value)) {
    if (std::abs(v) <= kMaxRobotLengthM) continue;
    throw InputError(InputErrorKind::kImplausibleValue, path, line,
                     key + " = " + Text(v) +
                         " is not a plausible length in metres for a wheeled robot (limit " +
                         Text(kMaxRobotLengthM) + " m): millimetres? write " + Text(v / 1000.0));
  }
}

// Where a wheel or castor sits around the robot ("angle_deg", "pivot_angle_deg"): spread around
// the robot by construction. Offsets, biases, drive, roller and steering angles are small or
// equal for every wheel and tell nothing about their unit.
bool IsMountingAngleKey(const std::string& key) {
  if (key != "angle_deg" && !EndsWith(key, "_angle_deg")) return false;
  for (const char* other : {"offset", "bias", "drive", "roller", "steering"}) {
    if (key.find(other) != std::string::npos) return false;
  }
  return true;
}

// The mounting-angle keys of the maps in one list (wheels, castors): radians where degrees are
// meant.
void CheckListAngles(const YAML::Node& list, const std::string& list_key, const std::string& path) {
  std::map<std::string, std::vector<std::pair<double, int>>> by_key;
  for (const YAML::Node& item : list) {
    if (!item.IsMap()) continue;
    for (const auto& entry : item) {
      if (!entry.first.IsScalar() || !IsMountingAngleKey(entry.first.Scalar())) continue;
      if (!entry.second.IsScalar()) continue;
      for (const auto& number : Numbers(entry.second))
        by_key[entry.first.Scalar()].push_back(number);
    }
  }
  for (const auto& [key, values] : by_key) {
    if (values.size() < 3) continue;
    double lo = values.front().first, hi = lo, largest = 0.0;
    for (const auto& [v, line] : values) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      largest = std::max(largest, std::abs(v));
    }
    // Wheels mounted around a robot spread over more than pi (half a turn) in radians; small
    // angles in degrees (drive-angle offsets of a degree or two) do not.
    if (largest > 2.0 * M_PI + 1e-9 || hi - lo <= M_PI) continue;
    std::string as_degrees;
    for (const auto& [v, line] : values) {
      as_degrees +=
          (as_degrees.empty() ? "" : ", ") + Text(std::round(v * 180.0 / M_PI * 100) / 100);
    }
    throw InputError(InputErrorKind::kImplausibleValue, path, values.front().second,
                     list_key + ": " + key + " values lie within 2 pi of each other (" + Text(lo) +
                         " to " + Text(hi) +
                         "): radians where the key says degrees? in degrees they would be " +
                         as_degrees);
  }
}

}  // namespace

void CheckRobotYamlUnits(const YAML::Node& root, const std::string& path) {
  // Iterative walk (the document's size and depth are bounded by LoadYamlFile).
  std::vector<YAML::Node> pending{root};
  while (!pending.empty()) {
    const YAML::Node node = pending.back();
    pending.pop_back();
    if (node.IsSequence()) {
      for (const YAML::Node& child : node) pending.push_back(child);
    } else if (node.IsMap()) {
      for (const auto& entry : node) {
        if (!entry.first.IsScalar()) continue;
        const std::string& key = entry.first.Scalar();
        if (EndsWith(key, "_m")) CheckLengths(key, entry.second, path);
        if (entry.second.IsSequence()) CheckListAngles(entry.second, key, path);
        pending.push_back(entry.second);
      }
    }
  }
}

}  // namespace fitcal::io
