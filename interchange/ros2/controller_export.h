#pragma once
// The parameter YAML a ros2_controllers controller reads, from a calibrated robot YAML (what
// `fitcal export ros2-control`, cli/export_ros2_control.h, calls). Each model registers the
// controllers it can be written for, with their writers, from its own folder
// (ModelExtras::controllers, models/model_extras.h; e.g. models/diff_drive/diff_drive_extras.cc);
// the export finds them through the registry:
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
// Joint names: in the robot's channel order (default: the channel names); they must be the
// URDF's joint names for the controller to load.

#include <string>
#include <vector>

#include "models/model_extras.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/run_log.h"
#include "validation/never_worse.h"
#include "validation/odometry_covariance.h"

namespace fitcal {

// The parameters and what the controller computes from them (models/model_extras.h).
using Ros2ControlExport = ControllerExport;

// The controllers the registered models write (ModelExtras::controllers), by name, sorted.
std::vector<std::string> Ros2Controllers();

// The ROS 2 distributions the export knows, oldest first; the default is the last (newest).
const std::vector<std::string>& RosDistros();

// Throws UsageError (io/command_failure.h) for an unknown controller, or a distribution that is
// not one of RosDistros() or does not ship it.
void CheckControllerDistro(const std::string& controller, const std::string& ros_distro);

// The export of a calibrated robot (read through the model registry; its values are the
// calibration; calibration_path names it in errors). The parameters are taken from the model by
// name (its parameter table, models/model_interface.h), never by position. Throws UsageError
// (one line) for an unknown controller, a model/controller mismatch, a geometry the controller
// cannot describe at all (e.g. mecanum rollers the wrong way), joints of the wrong length, an
// unknown distribution or a controller it does not ship.
Ros2ControlExport ExportRos2Control(const RobotModelPtr& calibrated,
                                    const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints,
                                    const std::string& ros_distro = RosDistros().back());

// The covariance keys of `controller` (ros__parameters lines, 4-space indent) holding `c`.
std::string Ros2CovarianceParameters(const std::string& controller, const OdometryCovariance& c);

// The exported parameters replayed on the held-out runs beside the nominal robot and the exact
// calibration: CF (Palacin Eq. 14) of each, and the odometry covariance of both calibrations.
struct ExportReplay {
  std::size_t runs = 0;
  std::string which;  // which runs: held out from the calibration, or none of them trained it
  double cf_nominal = 0.0, cf_exact = 0.0, cf_exported = 0.0;
  OdometryCovariance exported_covariance, exact_covariance;
  // The never-worse judgement of the exported parameters against the nominal (validation/
  // never_worse.h, the rule fit applies): worse on a kind of run, in drift or ATE, beyond the
  // runs' scatter refuses; what only warns is said beside the replay line.
  NeverWorseSaid never_worse;
  bool Worse() const { return cf_exported > cf_nominal || !never_worse.refusals.empty(); }
  // Empty unless Worse(): why nothing is written (exit 5 unless --allow-worse); `has_notes` adds
  // the hint that the controller leaves something out.
  std::string WorseRefusal(bool has_notes) const;
};

// `exact` is the calibration as read, `exported` what the controller computes from the export;
// the data set `logs` (whose robot must be the calibration's model) is read once. The twist
// covariance is per `publish_period_s` (0: the encoder period).
ExportReplay ReplayExport(const std::string& logs, const std::string& calibration_path,
                          const RobotModelPtr& exact, const Ros2ControlExport& exported,
                          double publish_period_s);

// The calibration file at `path` with `calibration.odometry_covariance` (one flow-style line
// right after `calibration:`, replacing an earlier one): the file stays a robot YAML every reader
// takes. Throws UsageError when it has no calibration block.
std::string CalibrationWithCovariance(const std::string& path, const OdometryCovariance& c);

}  // namespace fitcal
