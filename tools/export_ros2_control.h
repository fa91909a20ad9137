#pragma once
// `fitcal export ros2-control --calibration cal.yaml --controller <name> [--out file]`: the
// parameter YAML a ros2_controllers controller reads, from a calibrated robot YAML. Each model
// registers the controllers it can be written for, with their writers, from its own folder
// (ModelExtras::controllers, models/model_extras.h; e.g. models/diff_drive/diff_drive_extras.cc);
// this command finds them through the registry:
//
//   controller                   fitcal model               keys written (ros__parameters)
//   diff_drive_controller        diff_drive                 wheel_separation, wheel_radius,
//                                                           {left,right}_wheel_radius_multiplier,
//                                                           wheel_separation_multiplier (1.0),
//                                                           {left,right}_wheel_names,
//                                                           wheels_per_side (humble only)
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
// Per ROS 2 distribution (--ros-distro humble|jazzy|rolling, default the newest): only the keys
// that distribution's controller declares are written (tests/data/ros2_controllers/ keeps the
// declared names and types of each; ros2_io_test checks every export against them). humble has
// no omni_wheel_drive_controller; jazzy and rolling no longer declare wheels_per_side.
//
// diff_drive_controller represents a diff_drive calibration exactly (a radius multiplier per
// side). The others cannot: mecanum_drive_controller has one radius and one lx + ly for all
// wheels and assumes drive directions straight ahead; omni_wheel_drive_controller has one radius,
// one distance and equally spaced wheels; tricycle_controller has no steering offset. The export
// writes the best representable values (means over the wheels; the offset left out) and names
// every approximation in one line, with the exact value, its sign and where it goes.
//
// Covariance (validation/odometry_covariance.h, docs/ros2.md): with a data set, the errors of
// the exported parameters on the held-out runs give twist_covariance_diagonal (the twist's
// variance per message of --publish-rate, default the encoder period, the ground truth's own
// noise removed) and pose_covariance_diagonal (the variance after 1 m, with its growth law in
// --calibration-out), written where the controller declares them (diagonal_covariance.twist /
// .pose for omni_wheel_drive_controller); axes a planar robot does not measure (z, roll, pitch)
// get kUnmeasuredVariance. --calibration-out writes the exact calibration's own covariance into
// a copy of the calibration file (calibration.odometry_covariance).
//
// The calibrated parameters are taken from the model by name (its parameter table,
// models/model_interface.h: ParameterIndex), and the replay runs what the controller computes
// from the values as written (Ros2ControlExport::model, ::parameters): no YAML is written to be
// read back.
//
// With a data set (--logs) the exported parameters are replayed on its held-out runs - the runs
// the calibration did not train on, found as `report` finds them (validation/training_runs.h:
// by run id and fingerprint) - beside the nominal robot (the data set's robot.yaml) and the exact
// calibration (CF, Palacin Eq. 14). Parameters that replay worse than the nominal robot are not
// written (exit 5) unless --allow-worse.
//
// Joint names: --joints in the robot's channel order (default: the channel names); they must be
// the URDF's joint names for the controller to load.

#include <string>
#include <vector>

#include "models/model_extras.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/run_log.h"
#include "validation/odometry_covariance.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

// The parameters and what the controller computes from them (models/model_extras.h).
using Ros2ControlExport = ControllerExport;

// The controllers the registered models write (ModelExtras::controllers), by name, sorted.
std::vector<std::string> Ros2Controllers();

// The ROS 2 distributions the export knows, oldest first; the default is the last (newest).
const std::vector<std::string>& RosDistros();

// The export of a calibrated robot (read through the model registry; its values are the
// calibration; calibration_path names it in errors). The parameters are taken from the model by
// name (its parameter table, models/model_interface.h), never by position. Throws
// std::invalid_argument (one line) for an unknown controller, a model/controller mismatch, a
// geometry the controller cannot describe at all (e.g. mecanum rollers the wrong way), --joints of
// the wrong length, an unknown distribution or a controller it does not ship.
Ros2ControlExport ExportRos2Control(const RobotModelPtr& calibrated,
                                    const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints,
                                    const std::string& ros_distro = RosDistros().back());
// The same from the calibration file; io::InputError for a bad one.
Ros2ControlExport ExportRos2Control(const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints,
                                    const std::string& ros_distro = RosDistros().back());

// The covariance keys of `controller` (ros__parameters lines, 4-space indent) holding `c`.
std::string Ros2CovarianceParameters(const std::string& controller, const OdometryCovariance& c);

struct ExportRos2ControlOptions {
  std::string calibration;
  std::string controller;
  std::string node_name;  // default: the controller's name
  std::vector<std::string> joints;
  std::string out;   // empty: stdout
  std::string logs;  // optional data set: held-out CF nominal vs exact vs exported
  std::string ros_distro = RosDistros().back();
  bool allow_worse = false;  // write parameters that replay worse than the nominal robot
  // The interval the controller publishes its twist on (1 / its publish_rate); 0: the data set's
  // encoder period (a controller publishing on every encoder update).
  double publish_period_s = 0.0;
  // With logs: a copy of the calibration with its odometry covariance (validation/
  // odometry_covariance.h) in the calibration block; may be the calibration itself with force.
  std::string calibration_out;
  bool force = false;
};

// The runs of `logs` that validate `calibration_path`: those it did not train on (by recorded run
// id, as `report` splits; every run when it records none); `*which` says which. Throws
// io::InputError for a bad data set or calibration block, and UsageError (exit 2, as `report`)
// when it trained on every run.
// `held_out_logs`, when given, receives the same runs as loaded (ground-truth tracks included).
std::vector<AlignedRun> ExportHeldOutRuns(const std::string& calibration_path,
                                          const std::string& logs, const Robot& robot,
                                          std::string* which,
                                          std::vector<RunLog>* held_out_logs = nullptr);

// One line `fitcal export ros2-control: ...` and exit 1 (bad input), 2 (mismatch, bad options)
// or 5 (the parameters replay worse than the nominal robot; nothing written); notes one line
// each on stderr; 0 after writing.
// Declares every flag of `export ros2-control` on its subcommand `app`, bound to `options`.
void AddExportRos2ControlOptions(CLI::App& app, ExportRos2ControlOptions& options);

int RunExportRos2ControlCommand(const ExportRos2ControlOptions& options);

}  // namespace fitcal::tools
