#include "models/diff_drive/diff_drive_extras.h"

#include "io/ros2_parameter_yaml.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/diff_drive/diff_drive_trajectories.h"

namespace fitcal {

namespace {

using io::Ros2AsWritten;
using io::Ros2Double;

// diff_drive_controller represents the calibration exactly: a radius multiplier per side.
void DiffDriveParameters(const CalibratedRobot& c, const std::string& distro,
                         ControllerExport* out) {
  const int right = DiffDriveRightChannel(*c.model), left = 1 - right;
  const int k_right = c.Index("r_" + c.ChannelName(right));
  const int k_left = c.Index("r_" + c.ChannelName(left));
  const int k_separation = c.Index("wheel_separation");
  const std::vector<double>& p = c.robot().nominal;
  const double radius = 0.5 * (p[k_right] + p[k_left]);
  out->parameters_yaml +=
      "    left_wheel_names: " + io::Ros2NameList({c.joints[left]}) +
      "\n    right_wheel_names: " + io::Ros2NameList({c.joints[right]}) +
      // humble declares wheels_per_side (and overwrites it with the names' count); jazzy and
      // rolling no longer declare it, and an undeclared key is ignored there.
      (distro == "humble" ? "\n    wheels_per_side: 1" : "") +
      "\n    wheel_separation: " + Ros2Double(p[k_separation]) +
      "\n    wheel_radius: " + Ros2Double(radius) + "\n    wheel_separation_multiplier: 1.0" +
      "\n    left_wheel_radius_multiplier: " + Ros2Double(p[k_left] / radius) +
      "\n    right_wheel_radius_multiplier: " + Ros2Double(p[k_right] / radius) + "\n";
  // The controller's wheels: wheel_radius times each side's multiplier, the separation times 1.
  out->model = c.model;
  out->parameters = p;
  out->parameters[k_right] = Ros2AsWritten(radius) * Ros2AsWritten(p[k_right] / radius);
  out->parameters[k_left] = Ros2AsWritten(radius) * Ros2AsWritten(p[k_left] / radius);
  out->parameters[k_separation] = Ros2AsWritten(p[k_separation]);
}

std::vector<sim::TrajectorySpec> DiffDriveScenario(const RobotModelInterface& /*model*/,
                                                   const std::vector<double>& /*truth*/,
                                                   int repetitions) {
  sim::DiffDriveTrajectoryOptions shapes;
  shapes.circle_laps = 1.25;  // open arcs: the scale (sim/model_scenarios.h)
  return sim::DiffDriveCalibrationTrajectories(repetitions, shapes);
}

}  // namespace

ModelExtras DiffDriveExtras() {
  ModelExtras extras;
  extras.controllers = {{"diff_drive_controller", "humble jazzy rolling", &DiffDriveParameters}};
  // UMBmark-sized: a larger error leaves a 1 m square too far from closing for UMBmark
  // (sim/model_scenarios.h).
  extras.scenario.trajectories = &DiffDriveScenario;
  extras.scenario.truth_fraction = 0.025;
  extras.closed_forms = {{"umbmark", &DiffDriveUmbmark}};
  return extras;
}

}  // namespace fitcal
