#pragma once
// `fitcal export ros2-control --calibration cal.yaml --controller <name> [--out file]`: the
// parameter YAML a ros2_controllers controller reads, from a calibrated robot YAML:
//
//   controller                   fitcal model               keys written (ros__parameters)
//   diff_drive_controller        diff_drive                 wheel_separation, wheel_radius,
//                                                           {left,right}_wheel_radius_multiplier,
//                                                           wheel_separation_multiplier (1.0),
//                                                           {left,right}_wheel_names,
//                                                           wheels_per_side
//   mecanum_drive_controller     omni, 4 mecanum wheels     kinematics.wheels_radius,
//                                                           kinematics.sum_of_robot_center_
//                                                           projection_on_X_Y_axis, the four
//                                                           <corner>_wheel_command_joint_name
//   omni_wheel_drive_controller  omni3, omni (omni wheels)  wheel_radius, robot_radius,
//                                                           wheel_offset, wheel_names
//   tricycle_controller          tricycle                   wheelbase, wheel_radius,
//                                                           traction_joint_name,
//                                                           steering_joint_name
// (key names and nesting: each controller's generate_parameter_library file in
// ros-controls/ros2_controllers, src/*_parameter(s).yaml; tricycle_controller's radius key is
// `wheel_radius` - `traction_wheel_radius` belongs to bicycle_steering_controller.)
//
// diff_drive_controller represents a diff_drive calibration exactly (a radius multiplier per
// side). The others cannot: mecanum_drive_controller has one radius and one lx + ly for all
// wheels and assumes drive directions straight ahead; omni_wheel_drive_controller has one radius,
// one distance and equally spaced wheels; tricycle_controller has no steering offset. The export
// writes the best representable values (means over the wheels; the offset left out) and names
// every approximation in one line; with a data set it reports the held-out CF (Palacin Eq. 14)
// of the exact calibration and of the exported parameters.
//
// Joint names: --joints in the robot's channel order (default: the channel names); they must be
// the URDF's joint names for the controller to load.

#include <string>
#include <vector>

#include "models/model_interface.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

struct Ros2ControlExport {
  std::string parameters_yaml;     // `<node>:\n  ros__parameters:\n    ...` without the comments
  std::vector<std::string> notes;  // one line per parameter the controller cannot represent
};

// The controllers above, by name.
const std::vector<std::string>& Ros2Controllers();

// Throws io::InputError for a bad calibration file, std::invalid_argument (one line) for an
// unknown controller, a model/controller mismatch, a geometry the controller cannot describe at
// all (e.g. mecanum rollers the wrong way) or --joints of the wrong length.
Ros2ControlExport ExportRos2Control(const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints);

// fitcal's reader of such a YAML: the robot model (the calibrated robot's model, channels and
// names) whose nominal parameters are the kinematics the controller computes from it. `what`
// names the text in errors. Throws io::InputError for a missing key or a joint that is not the
// robot's.
RobotModelPtr ReadRos2ControlYaml(const std::string& yaml_text, const std::string& what,
                                  const std::string& calibration_path,
                                  const std::vector<std::string>& joints);

struct ExportRos2ControlOptions {
  std::string calibration;
  std::string controller;
  std::string node_name;  // default: the controller's name
  std::vector<std::string> joints;
  std::string out;   // empty: stdout
  std::string logs;  // optional data set: held-out CF exact vs exported
  bool force = false;
};

// One line `fitcal export ros2-control: ...` and exit 1 (bad input) or 2 (mismatch, bad
// options); notes one line each on stderr; 0 after writing.
// Declares every flag of `export ros2-control` on its subcommand `app`, bound to `options`.
void AddExportRos2ControlOptions(CLI::App& app, ExportRos2ControlOptions& options);

int RunExportRos2ControlCommand(const ExportRos2ControlOptions& options);

}  // namespace fitcal::tools
