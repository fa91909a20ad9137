#pragma once
// Values as a ROS 2 parameter YAML (ros__parameters) must hold them: every controller writer
// (models/model_extras.h) and the export command (cli/export_ros2_control.h) write through these.

#include <string>
#include <vector>

#include "odometry/robot.h"

namespace fitcal::io {

// A double with a decimal point (12 significant digits), else rclcpp types it as an integer and a
// double parameter refuses it.
std::string Ros2Double(double v);

// A value as the controller reads it back from the text Ros2Double wrote: a replay runs the
// parameters the controller will run.
double Ros2AsWritten(double v);

// Joint names as a flow list, each double-quoted and escaped (yaml_scalar.h): a quote in a URDF
// name stays YAML.
std::string Ros2NameList(const std::vector<std::string>& names);

// The joint of each of the robot's channels: `joints` (--joints) when given, else the channels'
// own names. Throws UsageError (exit 2) for a count other than the channels' or a name given
// twice: one joint for two wheels is no controller's (or bag's) wiring. Import and export share it.
std::vector<std::string> ChannelJointNames(const Robot& robot,
                                           const std::vector<std::string>& joints);

}  // namespace fitcal::io
