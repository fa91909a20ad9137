#include "models/diff_drive/diff_drive_model.h"

#include <algorithm>
#include <cctype>

#include "io/input_error.h"
#include "io/robot_yaml_blocks.h"
#include "io/yaml_reader.h"
#include "io/yaml_text.h"
#include "models/diff_drive/umbmark.h"
#include "models/mounted_model.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

using io::InputError;
using io::InputErrorKind;
using io::LineOf;

struct DiffDriveWheel {
  std::string name;
  std::string side;  // "right" or "left"
  double radius_m = 0.0;
  int line = 0;
};

DiffDriveWheel ReadWheel(const YAML::Node& node, const std::string& path, int index) {
  const std::string what = "wheel " + std::to_string(index + 1);
  io::YamlMap wheel(node, path, what);
  DiffDriveWheel w;
  w.line = LineOf(node);
  w.name = wheel.Name("name");
  const bool named_by_side = w.name == "right" || w.name == "left";
  w.side = wheel.Has("side") ? wheel.String("side") : named_by_side ? w.name : "";
  if (w.side != "right" && w.side != "left") {
    throw InputError(wheel.Has("side") ? InputErrorKind::kBadValue : InputErrorKind::kMissingKey,
                     path, w.line,
                     what + " '" + w.name +
                         "': side must be right or left (name the wheel right/left or add "
                         "side: right|left)");
  }
  if (named_by_side && w.side != w.name) {
    throw InputError(InputErrorKind::kBadValue, path, w.line,
                     what + " is named '" + w.name + "' but has side: " + w.side);
  }
  w.radius_m = wheel.Double("radius_m");
  if (!(w.radius_m > 0.0)) {
    throw InputError(InputErrorKind::kBadValue, path, w.line,
                     what + " '" + w.name + "': radius_m must be positive");
  }
  wheel.RejectUnread();
  return w;
}

std::vector<DiffDriveWheel> ReadWheels(io::YamlMap& robot_map, const std::string& path) {
  const YAML::Node wheels = robot_map.Required("wheels");
  io::ExpectYamlType(wheels, YAML::NodeType::Sequence, path, "robot.wheels");
  if (wheels.size() != diff_drive::kNumWheels) {
    throw InputError(
        InputErrorKind::kBadValue, path, LineOf(wheels),
        "a diff_drive robot has 2 wheels (right and left), found " + std::to_string(wheels.size()));
  }
  std::vector<DiffDriveWheel> out;
  for (int i = 0; i < diff_drive::kNumWheels; ++i) out.push_back(ReadWheel(wheels[i], path, i));
  if (out[0].name == out[1].name) {
    throw InputError(InputErrorKind::kBadValue, path, out[1].line,
                     "wheel name '" + out[1].name + "' is used twice");
  }
  if (out[0].side == out[1].side) {
    throw InputError(InputErrorKind::kBadValue, path, out[1].line,
                     "both wheels are on the " + out[1].side + "; one must be right, one left");
  }
  return out;
}

struct DiffDriveBox {
  Interval radius_m;
  Interval separation_m;
};

DiffDriveBox ReadBounds(io::YamlMap& robot_map, const std::string& path) {
  const YAML::Node node = robot_map.Required("bounds");
  io::YamlMap bounds(node, path, "bounds");
  DiffDriveBox box;
  box.radius_m = io::ReadBoundsPair(bounds, "radius_m", 1.0);
  box.separation_m = io::ReadBoundsPair(bounds, "wheel_separation_m", 1.0);
  bounds.RejectUnread();
  if (!(box.radius_m.lo > 0.0) || !(box.separation_m.lo > 0.0)) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(node),
                     "bounds on radius_m and wheel_separation_m must be positive");
  }
  return box;
}

template <int kRight>
RobotModelPtr MakeModel(Robot robot) {
  return std::make_shared<DiffDriveModelT<kRight>>(std::move(robot));
}

}  // namespace

Robot DiffDriveRobotDescription(const std::string& name,
                                const std::vector<std::string>& wheel_names) {
  Robot robot;
  robot.model = "diff_drive";
  robot.name = name;
  for (const std::string& w : wheel_names) {
    robot.channels.push_back({w, ChannelKind::kWheelRate, "w_" + w, "ticks_" + w});
  }
  for (const std::string& w : wheel_names) {
    robot.parameters.push_back({"r_" + w, "radius_m", ParameterUnit::kLength});
  }
  robot.parameters.push_back({"wheel_separation", "wheel_separation_m", ParameterUnit::kLength});
  return robot;
}

RobotModelPtr ReadDiffDriveModel(const YAML::Node& root, const std::string& path) {
  io::YamlMap robot_map(root, path, "robot");
  robot_map.String("model");
  const std::string name = robot_map.Name("name");
  const std::vector<DiffDriveWheel> wheels = ReadWheels(robot_map, path);
  const YAML::Node separation_node = robot_map.Required("wheel_separation_m");
  const double separation_m = robot_map.Double("wheel_separation_m");
  if (!(separation_m > 0.0)) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(separation_node),
                     "wheel_separation_m must be positive");
  }
  const DiffDriveBox box = ReadBounds(robot_map, path);
  Robot robot = DiffDriveRobotDescription(name, {wheels[0].name, wheels[1].name});
  robot.nominal = {wheels[0].radius_m, wheels[1].radius_m, separation_m};
  robot.bounds = {box.radius_m, box.radius_m, box.separation_m};
  for (int i = 0; i < diff_drive::kNumWheels; ++i) {
    if (!box.radius_m.Contains(wheels[i].radius_m)) {
      io::CheckNominalInsideBounds(robot, path, wheels[i].line);
    }
  }
  io::CheckNominalInsideBounds(robot, path, LineOf(separation_node));
  robot.encoder = io::ReadEncoderTicksNode(robot_map.Optional("encoder"), path);
  robot.effects = io::ReadEffectsNode(robot_map.Optional("effects"), path);
  robot_map.Optional("calibration");  // written by fitcal; informational when read back
  robot_map.RejectUnread();
  return wheels[0].side == "right" ? MakeModel<0>(std::move(robot))
                                   : MakeModel<1>(std::move(robot));
}

RobotModelPtr MakeDiffDriveModel(Robot robot) { return MakeModel<0>(std::move(robot)); }

int DiffDriveRightChannel(const RobotModelInterface& mounted_or_base) {
  const RobotModelInterface& model = BaseModel(mounted_or_base);
  if (dynamic_cast<const DiffDriveModelT<0>*>(&model) != nullptr) return 0;
  if (dynamic_cast<const DiffDriveModelT<1>*>(&model) != nullptr) return 1;
  return -1;
}

std::string DiffDriveRobotYaml(const Robot& robot, int right_channel, const std::vector<double>& p,
                               const std::vector<effects::EffectValue>& effects,
                               const std::string& calibration_block) {
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  out << YAML::BeginMap;
  out << YAML::Key << "model" << YAML::Value << "diff_drive";
  out << YAML::Key << "name" << YAML::Value << io::YamlText(robot.name);
  out << YAML::Key << "wheels" << YAML::Value << YAML::BeginSeq;
  for (int i = 0; i < diff_drive::kNumWheels; ++i) {
    const std::string& name = robot.channels[i].name;
    const std::string side = i == right_channel ? "right" : "left";
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << name;
    if (name != side) out << YAML::Key << "side" << YAML::Value << side;
    out << YAML::Key << "radius_m" << YAML::Value << p[i];
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "wheel_separation_m" << YAML::Value << p[diff_drive::kSeparationIndex];
  out << YAML::Key << "bounds" << YAML::Value << YAML::BeginMap;
  io::EmitBoundsPair(out, "radius_m", robot.bounds[0], 1.0);
  io::EmitBoundsPair(out, "wheel_separation_m", robot.bounds[diff_drive::kSeparationIndex], 1.0);
  out << YAML::EndMap;
  io::EmitEncoderAndEffects(out, robot, effects);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n" + calibration_block;
}

std::optional<ClosedFormCalibration> DiffDriveUmbmark(const RobotModelInterface& model,
                                                      const std::vector<AlignedRun>& training) {
  const Robot& robot = model.robot();
  const int right_channel = DiffDriveRightChannel(model);
  std::vector<umbmark::SquareReturnError> squares;
  int skipped = 0;
  for (const AlignedRun& run : training) {
    std::string label = run.trajectory;
    std::transform(label.begin(), label.end(), label.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (label.find("square") == std::string::npos) continue;
    const auto e = umbmark::MeasureSquare(model, robot.nominal, run);
    if (e) {
      squares.push_back(*e);
    } else {
      ++skipped;
    }
  }
  const int left_channel = 1 - right_channel;
  const umbmark::DiffDriveGeometry nominal{robot.nominal[right_channel],
                                           robot.nominal[left_channel],
                                           robot.nominal[diff_drive::kSeparationIndex]};
  const auto c = umbmark::Correct(squares, nominal);
  if (!c) return std::nullopt;
  ClosedFormCalibration calibration;
  calibration.parameters.resize(diff_drive::kNumParameters);
  calibration.parameters[right_channel] = c->corrected.r_right_m;
  calibration.parameters[left_channel] = c->corrected.r_left_m;
  calibration.parameters[diff_drive::kSeparationIndex] = c->corrected.separation_m;
  calibration.note = StrFormat(
      "Borenstein & Feng 1996 from %d CW + %d CCW squares (side %.3f m%s): alpha %.4f deg, beta "
      "%.4f deg, E_d %.6f, E_b %.6f",
      c->num_cw, c->num_ccw, c->side_m,
      skipped > 0 ? (", " + std::to_string(skipped) + " 'square' runs not one closed lap").c_str()
                  : "",
      c->alpha_rad * 180.0 / M_PI, c->beta_rad * 180.0 / M_PI, c->e_d, c->e_b);
  return calibration;
}

}  // namespace fitcal
