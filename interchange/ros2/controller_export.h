#pragma once
// The parameter YAML a ros2_controllers controller reads, from a calibrated robot YAML (what
// `fitcal export ros2-control` calls; docs/ros2.md). Each model registers the controllers it can
// be written for, with writers reading its parameters by name, from its own folder
// (ModelExtras::controllers, models/model_extras.h); the export finds them through the registry:
// diff_drive_controller (diff_drive), mecanum_drive_controller (omni, 4 mecanum wheels),
// omni_wheel_drive_controller (omni3, omni wheels), tricycle_controller (tricycle). Key names and
// nesting are each controller's generate_parameter_library file in ros2_controllers
// (tricycle_controller's radius is `wheel_radius`; `traction_wheel_radius` is
// bicycle_steering_controller's); only the keys the --ros-distro's controller declares are
// written (tests/data/ros2_controllers/, checked by ros2_io_test).
//
// Only diff_drive_controller represents its calibration exactly (a radius multiplier per side).
// The others get the best representable values (means over the wheels; the tricycle's steering
// offset left out), every approximation named in one line with the exact value, its sign and
// where it goes. The replay runs what the controller computes from the values as written
// (Ros2ControlExport::model, ::parameters): no YAML is written to be read back.
//
// With a data set (--logs) the export is replayed on the held-out runs (found as `report` finds
// them, validation/training_runs.h) beside the nominal and the exact calibration, judged
// never-worse, and gives the odometry covariance (validation/odometry_covariance.h): its
// unmeasured axes (z, roll, pitch) get kUnmeasuredVariance. Joint names, in the robot's channel
// order, must be the URDF's for the controller to load.

#include <string>
#include <vector>

#include "models/model_extras.h"
#include "models/model_interface.h"
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
// calibration; calibration_path names it in errors). Throws UsageError
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
