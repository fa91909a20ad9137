#include "io/robot_yaml.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

#include "io/input_error.h"
#include "io/robot_yaml_blocks.h"
#include "io/yaml_reader.h"
#include "io/yaml_text.h"
#include "io/yaml_units_check.h"
#include "odometry/pose2.h"

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

Omni3Robot ReadOmni3Robot(const std::string& path) {
  const YAML::Node root = LoadYamlFile(path);
  CheckRobotYamlUnits(root, path);
  YamlMap robot_map(root, path, "robot");
  const std::string model = robot_map.String("model");
  if (model != "omni3") {
    throw InputError(InputErrorKind::kUnknownModel, path,
                     robot_map.line(robot_map.Required("model")),
                     "model '" + model + "' is not omni3 (known: omni3)");
  }
  Omni3Robot robot;
  robot.name = robot_map.Name("name");
  const YAML::Node wheels = robot_map.Required("wheels");
  ExpectYamlType(wheels, YAML::NodeType::Sequence, path, "robot.wheels");
  if (wheels.size() != omni3::kNumWheels) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(wheels),
                     "an omni3 robot has 3 wheels, found " + std::to_string(wheels.size()));
  }
  std::set<std::string> names;
  for (int i = 0; i < omni3::kNumWheels; ++i) {
    const std::string what = "wheel " + std::to_string(i + 1);
    YamlMap wheel(wheels[i], path, what);
    robot.wheel_names[i] = wheel.Name("name");
    if (!names.insert(robot.wheel_names[i]).second) {
      throw InputError(InputErrorKind::kBadValue, path, LineOf(wheels[i]),
                       "wheel name '" + robot.wheel_names[i] + "' is used twice");
    }
    robot.nominal.distance_m[i] = wheel.Double("distance_m");
    robot.nominal.radius_m[i] = wheel.Double("radius_m");
    robot.nominal.angle_rad[i] = DegToRad(wheel.Double("angle_deg"));
    if (!(robot.nominal.distance_m[i] > 0.0) || !(robot.nominal.radius_m[i] > 0.0)) {
      throw InputError(InputErrorKind::kBadValue, path, LineOf(wheels[i]),
                       what + ": distance_m and radius_m must be positive");
    }
    wheel.RejectUnread();
  }
  YamlMap bounds(robot_map.Required("bounds"), path, "bounds");
  robot.bounds.distance_m = ReadBoundsPair(bounds, "distance_m", 1.0);
  robot.bounds.radius_m = ReadBoundsPair(bounds, "radius_m", 1.0);
  robot.bounds.angle_offset_rad = ReadBoundsPair(bounds, "angle_offset_deg", M_PI / 180.0);
  bounds.RejectUnread();
  if (!(robot.bounds.distance_m.lo > 0.0) || !(robot.bounds.radius_m.lo > 0.0)) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(robot_map.Required("bounds")),
                     "bounds on distance_m and radius_m must be positive");
  }
  // The nominal is the fit's start: it must lie inside the box the fit may search.
  const auto box = robot.ParameterBounds();
  const auto start = robot.nominal.ToArray();
  static const char* kGroup[] = {"distance_m", "radius_m", "angle_deg"};
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    if (!box[k].Contains(start[k])) {
      const int wheel = k % omni3::kNumWheels;
      throw InputError(
          InputErrorKind::kBadValue, path, LineOf(wheels[wheel]),
          "wheel " + robot.wheel_names[wheel] + ": " + kGroup[k / 3] + " lies outside its bounds");
    }
  }
  if (std::abs(omni3::InverseKinematicDenominator(start.data())) < 1e-9) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(wheels),
                     "the wheel angles and distances give a singular kinematic matrix");
  }
  robot.encoder = ReadEncoderTicksNode(robot_map.Optional("encoder"), path);
  robot.effects = ReadEffectsNode(robot_map.Optional("effects"), path);
  // Three wheel channels: a steering or wheel-pair effect would be replayed as nothing.
  for (std::size_t i = 0; i < robot.effects.size(); ++i) {
    const effects::EffectId id = robot.effects[i].id;
    if (effects::ChannelsCanCarry(id, omni3::kNumWheels, /*has_angle_channel=*/false)) continue;
    throw InputError(InputErrorKind::kBadValue, path, LineOf(root["effects"][i]),
                     std::string("effect ") + effects::Info(id).name +
                         " needs a steering angle or a pair of wheels; an omni3 robot cannot "
                         "carry it");
  }
  robot_map.Optional("calibration");  // written by fitcal; informational when read back
  robot_map.RejectUnread();
  return robot;
}

namespace {

void EmitTriple(YAML::Emitter& out, const std::string& key, const double* values, double scale) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < 3; ++i) out << values[i] * scale;
  out << YAML::EndSeq;
}

}  // namespace

std::string Omni3RobotYaml(const Omni3Robot& robot, const CalibrationRecord* calibration) {
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  out << YAML::BeginMap;
  out << YAML::Key << "model" << YAML::Value << "omni3";
  out << YAML::Key << "name" << YAML::Value << YamlText(robot.name);
  out << YAML::Key << "wheels" << YAML::Value << YAML::BeginSeq;
  for (int i = 0; i < omni3::kNumWheels; ++i) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << robot.wheel_names[i];
    out << YAML::Key << "distance_m" << YAML::Value << robot.nominal.distance_m[i];
    out << YAML::Key << "radius_m" << YAML::Value << robot.nominal.radius_m[i];
    out << YAML::Key << "angle_deg" << YAML::Value << RadToDeg(robot.nominal.angle_rad[i]);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "bounds" << YAML::Value << YAML::BeginMap;
  const auto pair = [&](const std::string& key, const Interval& v, double scale) {
    out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << v.lo * scale
        << v.hi * scale << YAML::EndSeq;
  };
  pair("distance_m", robot.bounds.distance_m, 1.0);
  pair("radius_m", robot.bounds.radius_m, 1.0);
  pair("angle_offset_deg", robot.bounds.angle_offset_rad, 180.0 / M_PI);
  out << YAML::EndMap;
  Robot common;
  common.encoder = robot.encoder;
  common.effects = robot.effects;
  EmitEncoderAndEffects(out, common);
  if (calibration != nullptr) {
    const CalibrationRecord& c = *calibration;
    out << YAML::Key << "calibration" << YAML::Value << YAML::BeginMap;
    EmitCalibrationOrigin(out, c);
    EmitCalibrationRunCounts(out, c);
    if (!c.training_run_ids.empty()) {
      out << YAML::Key << "training_run_ids" << YAML::Value << YAML::Flow << c.training_run_ids;
      out << YAML::Key << "training_fingerprint" << YAML::Value << YAML::DoubleQuoted
          << c.training_fingerprint;
    }
    out << YAML::Key << "at_bound" << YAML::Value << YAML::Flow << c.at_bound;
    EmitCalibrationCf(out, c);
    if (c.has_uncertainty) {
      out << YAML::Key << "sigma" << YAML::Value << YAML::BeginMap;
      EmitTriple(out, "distance_m", &c.sigma[omni3::kDistanceIndex], 1.0);
      EmitTriple(out, "radius_m", &c.sigma[omni3::kRadiusIndex], 1.0);
      EmitTriple(out, "angle_deg", &c.sigma[omni3::kAngleIndex], 180.0 / M_PI);
      out << YAML::EndMap;
      out << YAML::Key << "correlation" << YAML::Value << YAML::BeginSeq;
      out.SetDoublePrecision(4);
      for (int r = 0; r < omni3::kNumParameters; ++r) {
        out << YAML::Flow << YAML::BeginSeq;
        for (int k = 0; k < omni3::kNumParameters; ++k) out << c.correlation(r, k);
        out << YAML::EndSeq;
      }
      out << YAML::EndSeq;
      out.SetDoublePrecision(10);
    } else {
      out << YAML::Key << "sigma" << YAML::Value << YAML::Null;
    }
    out << YAML::Key << "inverse_kinematic_matrix" << YAML::Value << YAML::BeginSeq;
    out.SetDoublePrecision(16);
    for (int r = 0; r < 3; ++r) {
      out << YAML::Flow << YAML::BeginSeq;
      for (int k = 0; k < 3; ++k) out << c.inverse_kinematic_matrix(r, k);
      out << YAML::EndSeq;
    }
    out << YAML::EndSeq;
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace fitcal::io
