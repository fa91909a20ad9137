#pragma once
// A test-only robot model that lives entirely in the test tree and registers itself: a unicycle
// whose forward wheel (radius r) and turn encoder (gain k, rad of yaw per rad of encoder) are
// two channels. Its only purpose is to prove the seam: with nothing but this file it gets the
// generic replay, residuals, fit, result gate, YAML and wheel-order hypotheses.
//
//   dx = r w_drive dt,   dy = 0,   dtheta = k w_turn dt

#include <yaml-cpp/yaml.h>

#include "io/robot_yaml_blocks.h"
#include "models/kinematic_model.h"
#include "models/model_registry.h"

namespace fitcal::testing {

struct UnicycleKinematics {
  static constexpr int kNumParameters = 2;  // r, k

  template <typename T>
  static std::array<T, 2> Prepare(const T* p) {
    return {p[0], p[1]};
  }

  template <typename T, typename C>
  FITCAL_ALWAYS_INLINE static void BodyStep(const std::array<T, 2>& p, const C* w, double dt, T* dx,
                                            T* dy, T* dtheta) {
    *dx = p[0] * w[0] * dt;
    *dy = T(0.0);
    *dtheta = p[1] * w[1] * dt;
  }

  static bool ChannelsForTwist(const double* p, const Twist& twist, double* w) {
    if (twist.vy_m_s != 0.0) return false;
    w[0] = twist.vx_m_s / p[0];
    w[1] = twist.omega_rad_s / p[1];
    return true;
  }
};

class UnicycleModel : public KinematicModel<UnicycleKinematics> {
 public:
  using KinematicModel::KinematicModel;

  using RobotModelInterface::RobotYaml;
  std::string RobotYaml(const std::vector<double>& p,
                        const std::vector<effects::EffectValue>& effects,
                        const std::string& calibration_block) const override {
    YAML::Emitter out;
    out.SetDoublePrecision(12);
    out << YAML::BeginMap << YAML::Key << "model" << YAML::Value << "test_unicycle";
    out << YAML::Key << "name" << YAML::Value << robot_.name;
    out << YAML::Key << "radius_m" << YAML::Value << p[0];
    out << YAML::Key << "turn_gain" << YAML::Value << p[1];
    out << YAML::Key << "bounds" << YAML::Value << YAML::BeginMap;
    io::EmitBoundsPair(out, "radius_m", robot_.bounds[0], 1.0);
    io::EmitBoundsPair(out, "turn_gain", robot_.bounds[1], 1.0);
    out << YAML::EndMap;
    io::EmitEncoderAndEffects(out, robot_, effects);
    out << YAML::EndMap;
    return std::string(out.c_str()) + "\n" + calibration_block;
  }
};

inline RobotModelPtr ReadUnicycle(const YAML::Node& root, const std::string& path) {
  io::YamlMap map(root, path, "robot");
  map.String("model");
  Robot robot;
  robot.model = "test_unicycle";
  robot.name = map.String("name");
  robot.channels = {{"drive", ChannelKind::kWheelRate, "w_drive", "ticks_drive"},
                    {"turn", ChannelKind::kWheelRate, "w_turn", "ticks_turn"}};
  robot.parameters = {{"r", "radius_m", ParameterUnit::kLength},
                      {"k", "turn_gain", ParameterUnit::kLength}};
  robot.nominal = {map.Double("radius_m"), map.Double("turn_gain")};
  io::YamlMap bounds(map.Required("bounds"), path, "bounds");
  robot.bounds = {io::ReadBoundsPair(bounds, "radius_m", 1.0),
                  io::ReadBoundsPair(bounds, "turn_gain", 1.0)};
  bounds.RejectUnread();
  io::CheckNominalInsideBounds(robot, path, map.line(root));
  robot.encoder = io::ReadEncoderTicksNode(map.Optional("encoder"), path);
  robot.effects = io::ReadEffectsNode(map.Optional("effects"), path);
  map.Optional("calibration");
  map.RejectUnread();
  return std::make_shared<UnicycleModel>(std::move(robot));
}

inline const bool kUnicycleRegistered = RegisterModel(
    {"test_unicycle", "test-only unicycle (tests/models/unicycle_test_model.h)", &ReadUnicycle,
     "model: test_unicycle\nname: test\nradius_m: 0.05\nturn_gain: 0.5\n"
     "bounds: {radius_m: [0.04, 0.06], turn_gain: [0.4, 0.6]}\n",
     {}});

}  // namespace fitcal::testing
