#pragma once
// `fitcal export ros2-control --calibration cal.yaml --controller <name> [--out file]`: the
// parameter YAML a ros2_controllers controller reads, from a calibrated robot YAML, and with
// --logs its replay on the held-out runs and the odometry covariance. What is written and why is
// the library's (interchange/ros2/controller_export.h); the command reads the flags, checks its
// outputs, calls it, and prints or writes.

#include <string>
#include <vector>

#include "interchange/ros2/controller_export.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

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

// One line `fitcal export ros2-control: ...` and exit 1 (bad input), 2 (mismatch, bad options)
// or 5 (the parameters replay worse than the nominal robot; nothing written); notes one line
// each on stderr; 0 after writing.
// Declares every flag of `export ros2-control` on its subcommand `app`, bound to `options`.
void AddExportRos2ControlOptions(CLI::App& app, ExportRos2ControlOptions& options);

int RunExportRos2ControlCommand(const ExportRos2ControlOptions& options);

}  // namespace fitcal::tools
