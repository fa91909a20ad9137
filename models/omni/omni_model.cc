#include "models/omni/omni_model.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/input_error.h"
#include "io/robot_yaml_blocks.h"
#include "io/yaml_reader.h"
#include "models/mounted_model.h"
#include "models/omni/omni_model_build.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace omni_model_internal {

namespace {

std::string GaugeReason(const Robot& robot, int held, const Eigen::VectorXd& direction) {
  const ParameterInfo& h = robot.parameters[held];
  std::string with;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (k == held || std::abs(direction(k)) < 1e-9) continue;
    const ParameterInfo& q = robot.parameters[k];
    with += StrFormat("%s%s %+.3g %s/%s", with.empty() ? "" : ", ", q.name.c_str(),
                      direction(k) * q.DisplayScale() / h.DisplayScale(), q.DisplayUnit(),
                      h.DisplayUnit());
  }
  return "wheels that agree replay the same when " + h.name + " changes together with " +
         (with.empty() ? std::string("nothing else") : with) +
         ", so the odometry cannot determine it; held at its nominal to fix that direction";
}

}  // namespace

// The gauge: a basis Z of the directions the odometry cannot see, the held parameters chosen
// greedily (order below) while each pins a further direction, and the reason from Z re-expressed
// so that each column moves exactly one held parameter by one unit.
std::vector<HeldParameter> GaugeOfTwistJacobian(const Eigen::MatrixXd& g, const Robot& robot,
                                                const std::array<int, 3>& candidate_firsts,
                                                int wheels) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(g, Eigen::ComputeFullV);
  const Eigen::VectorXd s = svd.singularValues();
  int rank = 0;
  while (rank < s.size() && s(rank) > kRankTolerance * s(0)) ++rank;
  const int nullity = static_cast<int>(g.cols()) - rank;
  if (nullity == 0) return {};
  const Eigen::MatrixXd z = svd.matrixV().rightCols(nullity);
  // Candidates: angles, then distances, then radii, each from the last wheel backwards. Angles
  // pin the rows' translation directions, distances their yaw terms; radii carry the robot's
  // scale, which is what wears and what a box around the nominal should leave free (a radius
  // held at a wrong nominal would push the other wheels' angles by degrees per millimetre).
  std::vector<int> candidates;
  for (int first : candidate_firsts) {
    for (int i = wheels - 1; i >= 0; --i) candidates.push_back(first + i);
  }
  std::vector<int> held;
  for (int k : candidates) {
    if (static_cast<int>(held.size()) == nullity) break;
    Eigen::MatrixXd rows(held.size() + 1, nullity);
    for (std::size_t h = 0; h < held.size(); ++h) rows.row(h) = z.row(held[h]);
    rows.row(held.size()) = z.row(k);
    const Eigen::JacobiSVD<Eigen::MatrixXd> sub(rows);
    if (sub.singularValues().minCoeff() > 1e-6) held.push_back(k);
  }
  Eigen::MatrixXd zh(nullity, nullity);
  for (int h = 0; h < nullity; ++h) zh.row(h) = z.row(held[h]);
  Eigen::MatrixXd unit = z * zh.inverse();  // column h: held[h] moves by 1, other held by 0
  for (int k = 0; k < g.cols(); ++k) {
    unit.row(k) *= robot.parameters[k].RelativeScale(robot.nominal[k]);  // to physical units
  }
  std::vector<HeldParameter> out;
  for (int h = 0; h < nullity; ++h) {
    const Eigen::VectorXd direction = unit.col(h) / unit(held[h], h);
    out.push_back({held[h], GaugeReason(robot, held[h], direction)});
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.index < b.index; });
  return out;
}

}  // namespace omni_model_internal

namespace {

using io::InputError;
using io::InputErrorKind;
using io::LineOf;

// What is wrong with wheels[i] among those before it, or "".
std::string WheelProblem(const std::vector<OmniWheel>& wheels, std::size_t i) {
  const OmniWheel& w = wheels[i];
  for (std::size_t k = 0; k < i; ++k) {
    if (wheels[k].name == w.name) return "wheel name '" + w.name + "' is used twice";
  }
  if (!(w.distance_m > 0.0) || !(w.radius_m > 0.0)) {
    return "wheel " + w.name + ": distance_m and radius_m must be positive";
  }
  if (!(std::abs(w.roller_angle_rad) < DegToRad(89.0))) {
    return "wheel " + w.name + ": roller_angle_deg must lie inside (-89, 89) deg";
  }
  return "";
}

void CheckWheels(const std::vector<OmniWheel>& wheels) {
  if (wheels.size() < kOmniMinWheels || wheels.size() > kOmniMaxWheels) {
    throw std::invalid_argument("an omni robot has 3 to 8 wheels, found " +
                                std::to_string(wheels.size()));
  }
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    if (const std::string problem = WheelProblem(wheels, i); !problem.empty()) {
      throw std::invalid_argument(problem);
    }
  }
}

// The generic description: channels "w_<name>" / "ticks_<name>", parameters R_<name>,
// r_<name>, delta_<name> in the order of omni_kinematics.h.
Robot OmniRobotDescription(const std::string& name, const std::vector<OmniWheel>& wheels,
                           const OmniBounds& box) {
  Robot robot;
  robot.model = "omni";
  robot.name = name;
  for (const OmniWheel& w : wheels) {
    robot.channels.push_back({w.name, ChannelKind::kWheelRate, "w_" + w.name, "ticks_" + w.name});
  }
  for (const OmniWheel& w : wheels) {
    robot.parameters.push_back({"R_" + w.name, "distance_m", ParameterUnit::kLength});
    robot.nominal.push_back(w.distance_m);
    robot.bounds.push_back(box.distance_m);
  }
  for (const OmniWheel& w : wheels) {
    robot.parameters.push_back({"r_" + w.name, "radius_m", ParameterUnit::kLength});
    robot.nominal.push_back(w.radius_m);
    robot.bounds.push_back(box.radius_m);
  }
  for (const OmniWheel& w : wheels) {
    robot.parameters.push_back({"delta_" + w.name, "angle_offset_deg", ParameterUnit::kAngle});
    robot.nominal.push_back(w.angle_rad);
    robot.bounds.push_back(
        {w.angle_rad + box.angle_offset_rad.lo, w.angle_rad + box.angle_offset_rad.hi});
  }
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (!robot.bounds[k].Contains(robot.nominal[k])) {
      throw std::invalid_argument("the nominal " + robot.parameters[k].name +
                                  " lies outside its bounds");
    }
  }
  return robot;
}

OmniWheel ReadWheel(const YAML::Node& node, const std::string& path, int index) {
  io::YamlMap map(node, path, "wheel " + std::to_string(index + 1));
  OmniWheel w;
  w.name = map.Name("name");
  w.distance_m = map.Double("distance_m");
  w.angle_rad = DegToRad(map.Double("angle_deg"));
  w.radius_m = map.Double("radius_m");
  w.drive_angle_rad = map.Has("drive_angle_deg") ? DegToRad(map.Double("drive_angle_deg"))
                                                 : TangentialDriveAngle(w.angle_rad);
  w.roller_angle_rad = map.Has("roller_angle_deg") ? DegToRad(map.Double("roller_angle_deg")) : 0.0;
  map.RejectUnread();
  return w;
}

}  // namespace

OmniBounds ReadOmniBounds(io::YamlMap& robot_map, const std::string& path) {
  io::YamlMap bounds(robot_map.Required("bounds"), path, "bounds");
  OmniBounds box;
  box.distance_m = io::ReadBoundsPair(bounds, "distance_m", 1.0);
  box.radius_m = io::ReadBoundsPair(bounds, "radius_m", 1.0);
  box.angle_offset_rad = io::ReadBoundsPair(bounds, "angle_offset_deg", M_PI / 180.0);
  bounds.RejectUnread();
  if (!(box.distance_m.lo > 0.0) || !(box.radius_m.lo > 0.0)) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(robot_map.Required("bounds")),
                     "bounds on distance_m and radius_m must be positive");
  }
  return box;
}

RobotModelPtr MakeOmniModel(const std::string& name, const std::vector<OmniWheel>& wheels,
                            const OmniBounds& bounds, const std::optional<EncoderTicks>& encoder,
                            const std::vector<effects::EffectValue>& effect_values) {
  CheckWheels(wheels);
  Robot robot = OmniRobotDescription(name, wheels, bounds);
  robot.encoder = encoder;
  robot.effects = effect_values;
  using Builder = RobotModelPtr (*)(Robot, const std::vector<OmniWheel>&, const OmniBounds&);
  static constexpr Builder kBuilders[] = {&BuildOmniModel<3>, &BuildOmniModel<4>,
                                          &BuildOmniModel<5>, &BuildOmniModel<6>,
                                          &BuildOmniModel<7>, &BuildOmniModel<8>};
  return kBuilders[wheels.size() - kOmniMinWheels](std::move(robot), wheels, bounds);
}

RobotModelPtr ReadOmniModel(const YAML::Node& root, const std::string& path) {
  io::YamlMap robot_map(root, path, "robot");
  robot_map.String("model");
  const std::string name = robot_map.Name("name");
  const YAML::Node wheel_list = robot_map.Required("wheels");
  io::ExpectYamlType(wheel_list, YAML::NodeType::Sequence, path, "robot.wheels");
  std::vector<OmniWheel> wheels;
  for (std::size_t i = 0; i < wheel_list.size(); ++i) {
    wheels.push_back(ReadWheel(wheel_list[i], path, static_cast<int>(i)));
    // At the wheel's own line (the list's line named another wheel's problem).
    if (const std::string problem = WheelProblem(wheels, i); !problem.empty()) {
      throw InputError(InputErrorKind::kBadValue, path, LineOf(wheel_list[i]), problem);
    }
  }
  const OmniBounds box = ReadOmniBounds(robot_map, path);
  const std::optional<EncoderTicks> encoder =
      io::ReadEncoderTicksNode(robot_map.Optional("encoder"), path);
  const std::vector<effects::EffectValue> effect_values =
      io::ReadEffectsNode(robot_map.Optional("effects"), path);
  robot_map.Optional("calibration");  // written by fitcal; informational when read back
  robot_map.RejectUnread();
  try {
    return MakeOmniModel(name, wheels, box, encoder, effect_values);
  } catch (const std::invalid_argument& e) {
    throw InputError(InputErrorKind::kBadValue, path, LineOf(wheel_list), e.what());
  }
}

std::optional<std::vector<OmniWheel>> OmniWheelsOf(const RobotModelInterface& model,
                                                   const std::vector<double>& p) {
  const Robot& robot = model.robot();
  std::vector<OmniWheel> wheels;
  for (const ChannelInfo& channel : robot.channels) {
    const std::optional<int> distance = ParameterIndex(robot, "R_" + channel.name);
    const std::optional<int> radius = ParameterIndex(robot, "r_" + channel.name);
    const std::optional<int> angle = ParameterIndex(robot, "delta_" + channel.name);
    if (!distance || !radius || !angle) return std::nullopt;
    OmniWheel w{channel.name, p[*distance], p[*angle], p[*radius], 0.0, 0.0};
    w.drive_angle_rad = TangentialDriveAngle(w.angle_rad);  // Palacin's omni3 and the default
    wheels.push_back(w);
  }
  using Filler = bool (*)(const RobotModelInterface&, std::vector<OmniWheel>*);
  static constexpr Filler kFillers[] = {&FillOmniWheelMounts<3>, &FillOmniWheelMounts<4>,
                                        &FillOmniWheelMounts<5>, &FillOmniWheelMounts<6>,
                                        &FillOmniWheelMounts<7>, &FillOmniWheelMounts<8>};
  for (Filler fill : kFillers) {
    if (fill(BaseModel(model), &wheels)) break;
  }
  return wheels;
}

}  // namespace fitcal
