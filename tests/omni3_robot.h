#pragma once
// An omni3 robot in named fields, as the paper-reproduction tests hold it: its nominal geometry
// (Palacin Eq. 15) and the box within which the fit may move each parameter (Eq. 16), read from a
// robot YAML (ReadOmni3Robot) and put on the model seam (Omni3ModelOf), every fit running through
// the seam; APR-02's nominal robot; and the inverses of Eq. 3 and 6 the paper's tables are checked
// with. The product reads and writes omni3 robots through models/omni3/omni3_robot_model.h only.

#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/input_error.h"
#include "io/yaml_reader.h"
#include "models/model_registry.h"
#include "models/omni3/omni3_extras.h"
#include "models/omni3/omni3_parameters.h"
#include "models/omni3/omni3_robot_model.h"
#include "odometry/effects.h"
#include "odometry/robot.h"

namespace fitcal {

struct Omni3Bounds {
  Interval distance_m;        // absolute bounds on every R_i
  Interval radius_m;          // absolute bounds on every r_i
  Interval angle_offset_rad;  // bounds on delta_i - nominal delta_i (Eq. 16)
};

struct Omni3Robot {
  std::string name;
  std::array<std::string, omni3::kNumWheels> wheel_names{"a", "b", "c"};
  omni3::Parameters nominal;
  Omni3Bounds bounds;
  std::optional<EncoderTicks> encoder;  // set when the encoder logs are in ticks
  // Effects beyond the nine parameters (robot YAML `effects:`, written by `fitcal diagnose`);
  // replayed by odometry/effects.h ReplayStepsWithEffects.
  std::vector<effects::EffectValue> effects;

  // Per-parameter [lo, hi] in the flat order of omni3_parameters.h.
  std::array<Interval, omni3::kNumParameters> ParameterBounds() const {
    std::array<Interval, omni3::kNumParameters> out{};
    for (int i = 0; i < omni3::kNumWheels; ++i) {
      out[omni3::kDistanceIndex + i] = bounds.distance_m;
      out[omni3::kRadiusIndex + i] = bounds.radius_m;
      out[omni3::kAngleIndex + i] = {nominal.angle_rad[i] + bounds.angle_offset_rad.lo,
                                     nominal.angle_rad[i] + bounds.angle_offset_rad.hi};
    }
    return out;
  }
};

// The seam's view of an omni3 robot held in named fields, and its inverse.
inline std::shared_ptr<const Omni3Model> Omni3ModelOf(const Omni3Robot& omni3_robot) {
  Robot robot = Omni3RobotDescription(
      omni3_robot.name, {omni3_robot.wheel_names.begin(), omni3_robot.wheel_names.end()});
  const auto p = omni3_robot.nominal.ToArray();
  robot.nominal.assign(p.begin(), p.end());
  const auto box = omni3_robot.ParameterBounds();
  robot.bounds.assign(box.begin(), box.end());
  robot.encoder = omni3_robot.encoder;
  robot.effects = omni3_robot.effects;
  return std::make_shared<Omni3Model>(std::move(robot), omni3_robot.bounds.angle_offset_rad);
}

inline Omni3Robot Omni3RobotOf(const Omni3Model& model) {
  const Robot& robot = model.robot();
  Omni3Robot out;
  out.name = robot.name;
  for (int i = 0; i < omni3::kNumWheels; ++i) out.wheel_names[i] = robot.channels[i].name;
  out.nominal = omni3::Parameters::FromArray(robot.nominal.data());
  // One box per group (the YAML's schema; both constructors fill every wheel alike).
  out.bounds.distance_m = robot.bounds[omni3::kDistanceIndex];
  out.bounds.radius_m = robot.bounds[omni3::kRadiusIndex];
  out.bounds.angle_offset_rad = model.angle_offset_rad();
  out.encoder = robot.encoder;
  out.effects = robot.effects;
  return out;
}

// An omni3 robot YAML read as the registry reads every robot, in named fields. InputError, at the
// `model:` line, for a robot of another model.
inline Omni3Robot ReadOmni3Robot(const std::string& path) {
  const YAML::Node root = io::LoadYamlFile(path);
  io::ExpectYamlType(root, YAML::NodeType::Map, path, "robot file");
  // Another model's schema would fail on its first key; name the model instead.
  if (root["model"]) {
    const std::string model = io::YamlString(root["model"], path, "robot.model");
    if (model != "omni3") {
      throw io::InputError(io::InputErrorKind::kUnknownModel, path, io::LineOf(root["model"]),
                           "model '" + model + "' is not omni3 (an omni3 robot is expected here)");
    }
  }
  const RobotModelPtr model = ReadRobotModel(root, path);
  return Omni3RobotOf(dynamic_cast<const Omni3Model&>(*model));
}

// The omni3 model of the default Omni3Robot, made once: the kinematics for callers that hold omni3
// parameters without a robot (the parameters come with each call, the robot's values are not used).
inline const Omni3Model& DefaultOmni3Model() {
  static const std::shared_ptr<const Omni3Model> model = Omni3ModelOf(Omni3Robot{});
  return *model;
}

namespace sim {

// Palacin Eq. 15: the nominal parameters.
inline omni3::Parameters PalacinNominalParameters() {
  omni3::Parameters p;
  p.distance_m = {0.195, 0.195, 0.195};
  p.radius_m = {0.148, 0.148, 0.148};
  p.angle_rad = {60.0 * M_PI / 180.0, 180.0 * M_PI / 180.0, 300.0 * M_PI / 180.0};
  return p;
}

// APR-02 as data/robots/apr02.yaml describes it: Eq. 15 nominal, Eq. 16 bounds.
inline Omni3Robot PalacinApr02Robot() {
  Omni3Robot robot;
  robot.name = "apr02";
  robot.nominal = PalacinNominalParameters();
  robot.bounds.distance_m = {0.170, 0.220};  // Palacin Eq. 16
  robot.bounds.radius_m = {0.138, 0.158};
  robot.bounds.angle_offset_rad = {-2.0 * M_PI / 180.0, 2.0 * M_PI / 180.0};
  return robot;
}

}  // namespace sim

namespace omni3 {

// Inverts Eq. 3: from the rows of M back to the nine parameters. Row i is
// [-sin d_i, cos d_i, R_i] / r_i, so r_i = 1 / |(M_i0, M_i1)|, d_i = atan2(-M_i0, M_i1) and
// R_i = M_i2 r_i. Each angle is returned in the turn nearest to reference_angle_rad[i] (the
// nominal), since the matrix only knows angles modulo 2 pi.
inline Parameters ParametersFromKinematicMatrix(
    const Matrix3<double>& m, const std::array<double, kNumWheels>& reference_angle_rad) {
  Parameters out;
  for (int i = 0; i < kNumWheels; ++i) {
    const double radius = 1.0 / std::hypot(m(i, 0), m(i, 1));
    double angle = std::atan2(-m(i, 0), m(i, 1));
    angle += 2.0 * M_PI * std::round((reference_angle_rad[i] - angle) / (2.0 * M_PI));
    out.radius_m[i] = radius;
    out.angle_rad[i] = angle;
    out.distance_m[i] = m(i, 2) * radius;
  }
  return out;
}

inline Parameters ParametersFromInverseKinematicMatrix(
    const Matrix3<double>& m_inv, const std::array<double, kNumWheels>& reference_angle_rad) {
  return ParametersFromKinematicMatrix(m_inv.inverse(), reference_angle_rad);
}

// Wheel rates that realise a robot-frame motion command, Palacin Eq. 1 and Table A1:
// speed v (m/s) in direction alpha (rad, robot frame) while turning at omega (rad/s).
inline Eigen::Vector3d WheelRatesForCommand(const double* p, double speed_m_s, double alpha_rad,
                                            double omega_rad_s) {
  const Eigen::Vector3d v_robot(speed_m_s * std::cos(alpha_rad), speed_m_s * std::sin(alpha_rad),
                                omega_rad_s);
  return KinematicMatrix(p) * v_robot;
}

}  // namespace omni3

}  // namespace fitcal
