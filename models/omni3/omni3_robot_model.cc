#include "models/omni3/omni3_robot_model.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "io/input_error.h"
#include "io/robot_yaml_blocks.h"
#include "io/yaml_reader.h"
#include "io/yaml_text.h"

namespace fitcal {

namespace {

using io::InputError;
using io::InputErrorKind;
using io::LineOf;

}  // namespace

Robot Omni3RobotDescription(const std::string& name, const std::vector<std::string>& wheel_names) {
  Robot robot;
  robot.model = "omni3";
  robot.name = name;
  for (const std::string& w : wheel_names) {
    robot.channels.push_back({w, ChannelKind::kWheelRate, "w_" + w, "ticks_" + w});
  }
  // Palacin Eq. 15 order: R_i, then r_i, then delta_i.
  for (const std::string& w : wheel_names) {
    robot.parameters.push_back({"R_" + w, "distance_m", ParameterUnit::kLength});
  }
  for (const std::string& w : wheel_names) {
    robot.parameters.push_back({"r_" + w, "radius_m", ParameterUnit::kLength});
  }
  for (const std::string& w : wheel_names) {
    robot.parameters.push_back({"delta_" + w, "angle_offset_deg", ParameterUnit::kAngle});
  }
  return robot;
}

RobotModelPtr ReadOmni3Model(const YAML::Node& root, const std::string& path) {
  io::YamlMap robot_map(root, path, "robot");
  robot_map.String("model");
  const std::string name = robot_map.Name("name");
  const YAML::Node wheels = robot_map.Required("wheels");
  io::ExpectYamlType(wheels, YAML::NodeType::Sequence, path, "robot.wheels");
  if (wheels.size() != omni3::kNumWheels) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(wheels),
                     "an omni3 robot has 3 wheels, found " + std::to_string(wheels.size()));
  }
  std::vector<std::string> names;
  std::array<double, omni3::kNumParameters> p{};
  for (int i = 0; i < omni3::kNumWheels; ++i) {
    const std::string what = "wheel " + std::to_string(i + 1);
    io::YamlMap wheel(wheels[i], path, what);
    names.push_back(wheel.Name("name"));
    if (std::count(names.begin(), names.end(), names.back()) > 1) {
      throw InputError(InputErrorKind::kBadValue, path, LineOf(wheels[i]),
                       "wheel name '" + names.back() + "' is used twice");
    }
    p[omni3::kDistanceIndex + i] = wheel.Double("distance_m");
    p[omni3::kRadiusIndex + i] = wheel.Double("radius_m");
    p[omni3::kAngleIndex + i] = DegToRad(wheel.Double("angle_deg"));
    if (!(p[omni3::kDistanceIndex + i] > 0.0) || !(p[omni3::kRadiusIndex + i] > 0.0)) {
      throw InputError(InputErrorKind::kBadValue, path, LineOf(wheels[i]),
                       what + ": distance_m and radius_m must be positive");
    }
    wheel.RejectUnread();
  }
  const OmniBounds box = ReadOmniBounds(robot_map, path);
  Robot robot = Omni3RobotDescription(name, names);
  robot.nominal.assign(p.begin(), p.end());
  robot.bounds = Omni3ParameterBounds(robot.nominal, box);
  for (int k = 0; k < robot.NumParameters(); ++k) {
    // Named at the line of its wheel (parameters are grouped by kind, three wheels each).
    if (!robot.bounds[k].Contains(robot.nominal[k])) {
      io::CheckNominalInsideBounds(robot, path, LineOf(wheels[k % omni3::kNumWheels]));
    }
  }
  if (std::abs(omni3::InverseKinematicDenominator(p.data())) < 1e-9) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(wheels),
                     "the wheel angles and distances give a singular kinematic matrix");
  }
  robot.encoder = io::ReadEncoderTicksNode(robot_map.Optional("encoder"), path);
  robot.effects = io::ReadEffectsNode(robot_map.Optional("effects"), path);
  robot_map.Optional("calibration");  // written by fitcal; informational when read back
  robot_map.RejectUnread();
  return MakeOmni3Model(std::move(robot), box.angle_offset_rad);
}

RobotModelPtr MakeOmni3Model(Robot robot, Interval angle_offset_rad) {
  return std::make_shared<Omni3Model>(std::move(robot), angle_offset_rad);
}

std::vector<Interval> Omni3ParameterBounds(const std::vector<double>& nominal,
                                           const OmniBounds& box) {
  std::vector<Interval> bounds(omni3::kNumWheels, box.distance_m);
  bounds.insert(bounds.end(), omni3::kNumWheels, box.radius_m);
  for (int i = 0; i < omni3::kNumWheels; ++i) {
    const double delta = nominal[omni3::kAngleIndex + i];
    bounds.push_back({delta + box.angle_offset_rad.lo, delta + box.angle_offset_rad.hi});
  }
  return bounds;
}

std::string Omni3Model::RobotYaml(const std::vector<double>& p,
                                  const std::vector<effects::EffectValue>& effects,
                                  const std::string& calibration_block) const {
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  out << YAML::BeginMap;
  out << YAML::Key << "model" << YAML::Value << "omni3";
  out << YAML::Key << "name" << YAML::Value << io::YamlText(robot_.name);
  out << YAML::Key << "wheels" << YAML::Value << YAML::BeginSeq;
  for (int i = 0; i < omni3::kNumWheels; ++i) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << io::YamlText(robot_.channels[i].name);
    out << YAML::Key << "distance_m" << YAML::Value << p[omni3::kDistanceIndex + i];
    out << YAML::Key << "radius_m" << YAML::Value << p[omni3::kRadiusIndex + i];
    out << YAML::Key << "angle_deg" << YAML::Value << RadToDeg(p[omni3::kAngleIndex + i]);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "bounds" << YAML::Value << YAML::BeginMap;
  io::EmitBoundsPair(out, "distance_m", robot_.bounds[omni3::kDistanceIndex], 1.0);
  io::EmitBoundsPair(out, "radius_m", robot_.bounds[omni3::kRadiusIndex], 1.0);
  io::EmitBoundsPair(out, "angle_offset_deg", angle_offset_rad_, 180.0 / M_PI);
  out << YAML::EndMap;
  io::EmitEncoderAndEffects(out, robot_, effects);
  out << YAML::EndMap;
  std::string text = std::string(out.c_str()) + "\n";
  if (calibration_block.empty()) return text;
  // M^-1 of Eq. 6 for firmware that takes the matrix.
  const Eigen::Matrix3d m_inv = omni3::InverseKinematicMatrix(p.data());
  return text + calibration_block + io::CalibrationMatrixYaml("inverse_kinematic_matrix", m_inv) +
         "\n";
}

}  // namespace fitcal
