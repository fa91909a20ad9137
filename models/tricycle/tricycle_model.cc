#include "models/tricycle/tricycle_model.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "io/input_error.h"
#include "io/robot_yaml_blocks.h"
#include "io/yaml_reader.h"
#include "io/yaml_text.h"

namespace fitcal {

namespace {

using io::InputError;
using io::InputErrorKind;
using io::LineOf;
using K = TricycleKinematics;

constexpr const char* kDefaultTractionName = "traction";
constexpr const char* kSteeringColumn = "steering";
// A steering offset is a small mounting/zeroing error; beyond a right angle the "offset" would
// swap forward and sideways.
constexpr double kMaxSteeringOffsetDeg = 90.0;
constexpr const char* kGainKey = "steering_gain";
constexpr double kDefaultGainFactor = 10.0;

void RequirePositive(double v, const YAML::Node& node, const std::string& path,
                     const std::string& what, const std::string& hint = "") {
  if (!(v > 0.0)) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(node),
                     what + " must be positive" + hint);
  }
}

// A steered wheel behind the fixed axle (a forklift's) turns the body the other way for the same
// reading (w = -v sin(delta) / L about the fixed axle): this model with the steering reading
// negated. Said where a negative wheelbase or gain is refused; "must be positive" alone left a
// user no way on.
constexpr const char* kRearSteeredHint =
    " (the steered wheel ahead of the fixed axle; one behind it is this model with the steering "
    "angle's sign flipped in the logs)";

// `bounds:` - absolute boxes, lengths positive, the offset within +-90 deg.
// With a steering gain (`gain`), its box too: bounds.steering_gain, or by default a factor of
// 10 either way of the nominal (a linkage's ratio is known to that; the maker's guess of it can
// be off several times).
std::vector<Interval> ReadTricycleBounds(io::YamlMap& robot_map, const std::string& path,
                                         std::optional<double> gain) {
  const YAML::Node node = robot_map.Required("bounds");
  io::YamlMap bounds(node, path, "bounds");
  std::vector<Interval> box(gain ? TricycleGainKinematics::kNumParameters : K::kNumParameters);
  box[K::kRadiusIndex] = io::ReadBoundsPair(bounds, "radius_m", 1.0);
  box[K::kWheelbaseIndex] = io::ReadBoundsPair(bounds, "wheelbase_m", 1.0);
  box[K::kSteeringOffsetIndex] = io::ReadBoundsPair(bounds, "steering_offset_deg", M_PI / 180.0);
  if (gain) {
    Interval& g = box[TricycleGainKinematics::kSteeringGainIndex];
    g = bounds.Has(kGainKey) ? io::ReadBoundsPair(bounds, kGainKey, 1.0)
                             : Interval{*gain / kDefaultGainFactor, *gain * kDefaultGainFactor};
    if (!(g.lo > 0.0)) {
      throw InputError(InputErrorKind::kBadValue, path, LineOf(node),
                       "bounds.steering_gain must be positive");
    }
  }
  bounds.RejectUnread();
  if (!(box[K::kRadiusIndex].lo > 0.0) || !(box[K::kWheelbaseIndex].lo > 0.0)) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(node),
                     "bounds on radius_m and wheelbase_m must be positive");
  }
  const Interval& offset = box[K::kSteeringOffsetIndex];
  if (!(std::max(std::abs(offset.lo), std::abs(offset.hi)) < DegToRad(kMaxSteeringOffsetDeg))) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(node),
                     "bounds.steering_offset_deg must lie within (-90, 90)");
  }
  return box;
}

}  // namespace

Robot TricycleRobotDescription(const std::string& name, const std::string& traction_name,
                               bool with_gain) {
  Robot robot;
  robot.model = "tricycle";
  robot.name = name;
  robot.channels.resize(K::kNumChannels);
  robot.channels[K::kTractionChannel] = {traction_name, ChannelKind::kWheelRate,
                                         "w_" + traction_name, "ticks_" + traction_name};
  robot.channels[K::kSteeringChannel] = {kSteeringColumn, ChannelKind::kAngle, kSteeringColumn, ""};
  robot.parameters.resize(K::kNumParameters);
  robot.parameters[K::kRadiusIndex] = {"r_" + traction_name, "radius_m", ParameterUnit::kLength};
  robot.parameters[K::kWheelbaseIndex] = {"wheelbase", "wheelbase_m", ParameterUnit::kLength};
  robot.parameters[K::kSteeringOffsetIndex] = {"steering_offset", "steering_offset_deg",
                                               ParameterUnit::kAngle};
  // The wheel's angle per measured angle: dimensionless (its change is printed in %).
  if (with_gain) robot.parameters.push_back({kGainKey, kGainKey, ParameterUnit::kRatio});
  return robot;
}

RobotModelPtr ReadTricycleModel(const YAML::Node& root, const std::string& path) {
  io::YamlMap robot_map(root, path, "robot");
  robot_map.String("model");
  const std::string name = robot_map.Name("name");
  const YAML::Node wheel_node = robot_map.Required("traction_wheel");
  io::YamlMap wheel(wheel_node, path, "traction_wheel");
  const std::string traction_name =
      wheel.Has("name") ? wheel.Name("name") : std::string(kDefaultTractionName);
  // A CSV column name is built from the traction wheel's name.
  if (!io::IsColumnSafe(traction_name) || traction_name == kSteeringColumn) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(wheel_node),
                     "traction_wheel.name '" + traction_name +
                         "' must be letters, digits and '_' and not 'steering'");
  }
  std::vector<double> p(K::kNumParameters);
  p[K::kRadiusIndex] = wheel.Double("radius_m");
  RequirePositive(p[K::kRadiusIndex], wheel.Required("radius_m"), path, "traction_wheel.radius_m");
  wheel.RejectUnread();
  p[K::kWheelbaseIndex] = robot_map.Double("wheelbase_m");
  RequirePositive(p[K::kWheelbaseIndex], robot_map.Required("wheelbase_m"), path, "wheelbase_m",
                  kRearSteeredHint);
  p[K::kSteeringOffsetIndex] = DegToRad(robot_map.Double("steering_offset_deg"));
  std::optional<double> gain;
  if (robot_map.Has(kGainKey)) {
    gain = robot_map.Double(kGainKey);
    RequirePositive(*gain, robot_map.Required(kGainKey), path, kGainKey, kRearSteeredHint);
    p.push_back(*gain);
  }

  Robot robot = TricycleRobotDescription(name, traction_name, gain.has_value());
  robot.nominal = p;
  robot.bounds = ReadTricycleBounds(robot_map, path, gain);
  io::CheckNominalInsideBounds(robot, path, LineOf(robot_map.Required("bounds")));
  robot.encoder = io::ReadEncoderTicksNode(robot_map.Optional("encoder"), path);
  io::ReadAngleEncoders(robot_map, &robot);
  robot.effects = io::ReadEffectsNode(robot_map.Optional("effects"), path);
  robot_map.Optional("calibration");  // written by fitcal; informational when read back
  robot_map.RejectUnread();
  return MakeTricycleModel(std::move(robot));
}

RobotModelPtr MakeTricycleModel(Robot robot) {
  if (ParameterIndex(robot, kGainKey)) return std::make_shared<TricycleGainModel>(std::move(robot));
  return std::make_shared<TricycleModel>(std::move(robot));
}

std::string TricycleRobotYaml(const Robot& robot, const std::vector<double>& p,
                              const std::vector<effects::EffectValue>& effects,
                              const std::string& calibration_block) {
  const bool with_gain = robot.NumParameters() == TricycleGainKinematics::kNumParameters;
  const std::string& traction_name = robot.channels[K::kTractionChannel].name;
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  out << YAML::BeginMap;
  out << YAML::Key << "model" << YAML::Value << "tricycle";
  out << YAML::Key << "name" << YAML::Value << io::YamlText(robot.name);
  out << YAML::Key << "traction_wheel" << YAML::Value << YAML::Flow << YAML::BeginMap;
  if (traction_name != kDefaultTractionName) {
    out << YAML::Key << "name" << YAML::Value << traction_name;
  }
  out << YAML::Key << "radius_m" << YAML::Value << p[K::kRadiusIndex] << YAML::EndMap;
  out << YAML::Key << "wheelbase_m" << YAML::Value << p[K::kWheelbaseIndex];
  out << YAML::Key << "steering_offset_deg" << YAML::Value << RadToDeg(p[K::kSteeringOffsetIndex]);
  if (with_gain) {
    out << YAML::Key << kGainKey << YAML::Value << p[TricycleGainKinematics::kSteeringGainIndex];
  }
  out << YAML::Key << "bounds" << YAML::Value << YAML::BeginMap;
  io::EmitBoundsPair(out, "radius_m", robot.bounds[K::kRadiusIndex], 1.0);
  io::EmitBoundsPair(out, "wheelbase_m", robot.bounds[K::kWheelbaseIndex], 1.0);
  io::EmitBoundsPair(out, "steering_offset_deg", robot.bounds[K::kSteeringOffsetIndex],
                     180.0 / M_PI);
  if (with_gain) {
    io::EmitBoundsPair(out, kGainKey, robot.bounds[TricycleGainKinematics::kSteeringGainIndex],
                       1.0);
  }
  out << YAML::EndMap;
  io::EmitEncoderAndEffects(out, robot, effects);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n" + calibration_block;
}

template class TricycleModelT<false>;
template class TricycleModelT<true>;

}  // namespace fitcal
