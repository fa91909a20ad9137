#include "models/tricycle/tricycle_extras.h"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/ros2_parameter_yaml.h"
#include "io/yaml_scalar.h"
#include "models/tricycle/tricycle_kinematics.h"
#include "models/tricycle/tricycle_trajectories.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

constexpr double kDeg = M_PI / 180.0;

// tricycle_controller has no steering offset and no steering gain: the values it has, and a note
// on where each of the others goes.
void TricycleParameters(const CalibratedRobot& c, const std::string&, ControllerExport* out) {
  using K = TricycleKinematics;
  const std::string& traction = c.joints[K::kTractionChannel];
  const std::string& steering = c.joints[K::kSteeringChannel];
  const int k_radius = c.Index("r_" + c.ChannelName(K::kTractionChannel));
  const int k_wheelbase = c.Index("wheelbase"), k_offset = c.Index("steering_offset");
  const std::vector<double>& p = c.robot().nominal;
  const double offset_rad = p[k_offset];
  if (offset_rad != 0.0) {
    // models/tricycle/tricycle_kinematics.h: true steering = measured + phi_0. The controller
    // reads the steering joint's state as the true angle, so the joint must report phi_0 more:
    // ros2_control's SimpleTransmission computes joint = actuator / reduction + offset, which
    // also shifts the commands the same way.
    out->notes.push_back(
        StrFormat("tricycle_controller has no steering offset: add %+.9g rad (%+.6f deg) to "
                  "the steering joint '%s' position (true steering = measured %+.6f deg), e.g. "
                  "<offset>%.9g</offset> in its SimpleTransmission <joint> in the URDF "
                  "(joint = actuator / reduction + offset), or zero the steering encoder there",
                  offset_rad, offset_rad / kDeg, steering.c_str(), offset_rad / kDeg, offset_rad));
  }
  out->parameters_yaml += "    traction_joint_name: " + io::YamlDoubleQuoted(traction) +
                          "\n    steering_joint_name: " + io::YamlDoubleQuoted(steering) +
                          "\n    wheelbase: " + io::Ros2Double(p[k_wheelbase]) +
                          "\n    wheel_radius: " + io::Ros2Double(p[k_radius]) + "\n";
  // The controller's tricycle: these values, no steering offset and no steering gain.
  out->model = c.model;
  out->parameters = p;
  out->parameters[k_radius] = io::Ros2AsWritten(p[k_radius]);
  out->parameters[k_wheelbase] = io::Ros2AsWritten(p[k_wheelbase]);
  out->parameters[k_offset] = 0.0;
  if (const std::optional<int> k_gain = ParameterIndex(c.robot(), "steering_gain")) {
    // Wheel angle = k x measured + phi_0 (tricycle_kinematics.h T3). The controller reads the
    // steering joint as the wheel's angle; a SimpleTransmission's joint = actuator / reduction.
    out->notes.push_back(
        StrFormat("tricycle_controller has no steering gain: the steering joint '%s' must report "
                  "%.9g times the measured angle, e.g. <mechanicalReduction>%.9g"
                  "</mechanicalReduction> in its SimpleTransmission (joint = actuator / "
                  "reduction), before the offset above",
                  steering.c_str(), p[*k_gain], 1.0 / p[*k_gain]));
    out->parameters[*k_gain] = 1.0;
  }
}

// Circles are commanded by steering angle through the nominal wheelbase (the robot's belief);
// how far the wheel can steer is the true robot's: its column, read through the true gain, must
// stay readable (sim::TricycleReadableSteeringDeg), so circles beyond that are left out and the
// squares turn on arcs at that steering instead of in place.
std::vector<sim::TrajectorySpec> TricycleScenario(const RobotModelInterface& model,
                                                  const std::vector<double>& truth,
                                                  int repetitions) {
  const Robot& robot = model.robot();
  sim::TricycleTrajectoryOptions shapes;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (robot.parameters[k].group == "wheelbase_m") shapes.wheelbase_m = robot.nominal[k];
  }
  const std::optional<int> k_gain = ParameterIndex(robot, "steering_gain");
  const std::optional<int> k_offset = ParameterIndex(robot, "steering_offset");
  shapes.max_steering_deg = sim::TricycleReadableSteeringDeg(k_gain ? truth[*k_gain] : 1.0,
                                                             k_offset ? truth[*k_offset] : 0.0);
  std::vector<double> circles;
  for (double deg : shapes.steering_deg) {
    if (deg <= shapes.max_steering_deg) circles.push_back(deg);
  }
  if (circles.empty()) {
    throw std::invalid_argument(
        "the true steering gain reads at most " + std::to_string(shapes.max_steering_deg) +
        " deg of wheel steering: too little to drive the calibration circles");
  }
  shapes.steering_deg = circles;
  shapes.repetitions = repetitions;
  return sim::TricycleTrajectories(shapes);
}

}  // namespace

ModelExtras TricycleExtras() {
  ModelExtras extras;
  extras.controllers = {{"tricycle_controller", "humble jazzy rolling", &TricycleParameters}};
  extras.scenario.trajectories = &TricycleScenario;
  return extras;
}

}  // namespace fitcal
