#include "cli/export_ros2_control.h"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "cli/cli_validators.h"
#include "cli/dataset_command.h"
#include "io/atomic_file.h"
#include "io/command_failure.h"
#include "io/output_guard.h"
#include "io/text_file.h"
#include "io/yaml_scalar.h"
#include "models/model_registry.h"
#include "odometry/text_format.h"

namespace fitcal::tools {
namespace {

std::string ReplayLine(const ExportRos2ControlOptions& o, const ExportReplay& r) {
  return StrFormat(
      "CF (Palacin Eq. 14, m and rad) over %zu runs of %s %s: nominal robot %.6f, "
      "exact calibration %.6f, these parameters %.6f (%+.1f %% vs exact)",
      r.runs, o.logs.c_str(), r.which.c_str(), r.cf_nominal, r.cf_exact, r.cf_exported,
      100.0 * (r.cf_exported / r.cf_exact - 1.0));
}

std::string CovarianceLine(const OdometryCovariance& c) {
  constexpr const char* kAxes[] = {"vx", "vy", "omega"};
  constexpr const char* kPoseAxes[] = {"x", "y", "theta"};
  std::string unresolved;
  for (int a = 0; a < 6; ++a) {
    const bool twist = a < 3;
    if (!(twist ? c.twist_unresolved[a] : c.pose_unresolved[a - 3])) continue;
    unresolved += (unresolved.empty() ? "" : ", ") +
                  std::string(twist ? "twist " : "pose ") + (twist ? kAxes[a] : kPoseAxes[a - 3]);
  }
  if (!unresolved.empty()) {
    unresolved = "; " + unresolved +
                 ": no growth resolved above the ground truth's noise, the bound its windows set";
  }
  return StrFormat(
      "odometry covariance from %zu held-out runs (%zu windows; twist per message of %.4g s): "
      "twist sigma vx %.4g m/s, vy %.4g m/s, omega %.4g rad/s; pose sigma after 1 m x %.4g m, "
      "y %.4g m, theta %.4g rad, growing as d^%.2f, d^%.2f, d^%.2f; ground truth's own noise "
      "removed: %.3g m, %.3g m, %.3g rad%s",
      c.runs, c.windows, c.interval_s, std::sqrt(c.twist_variance[0]),
      std::sqrt(c.twist_variance[1]), std::sqrt(c.twist_variance[2]),
      std::sqrt(c.pose_variance_1m[0]), std::sqrt(c.pose_variance_1m[1]),
      std::sqrt(c.pose_variance_1m[2]), 0.5 * c.pose_growth_exponent[0],
      0.5 * c.pose_growth_exponent[1], 0.5 * c.pose_growth_exponent[2],
      std::sqrt(c.ground_truth_variance[0]), std::sqrt(c.ground_truth_variance[1]),
      std::sqrt(c.ground_truth_variance[2]), unresolved.c_str());
}

}  // namespace

void AddExportRos2ControlOptions(CLI::App& app, ExportRos2ControlOptions& o) {
  app.add_option("--calibration", o.calibration, "Calibrated robot YAML (from fit)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("--controller", o.controller, "One of " + io::Joined(Ros2Controllers(), ", "))
      ->required();
  app.add_option("--node-name", o.node_name, "Top-level key (default: the controller's name)");
  app.add_option("--joints", o.joints,
                 "URDF joint names in the robot's channel order (default: the channel names)")
      ->delimiter(',')
      ->check(JointNameValidator());
  app.add_option("--out", o.out, "File to write (atomically; default: stdout)");
  CLI::Option* logs = app.add_option("--logs", o.logs,
                 "Data set: replay the exported parameters on its held-out runs beside the "
                 "nominal robot and the exact calibration; refuse them if worse than nominal")
      ->check(CLI::ExistingDirectory);
  app.add_option("--ros-distro", o.ros_distro,
                 "ROS 2 distribution (" + io::Joined(RosDistros(), "|") +
                     "): only the keys it declares are written")
      ->capture_default_str();
  // Both act on the replay of --logs; without it they would be dropped in silence.
  app.add_flag("--allow-worse", o.allow_worse,
               "With --logs: write the parameters even when they replay worse than the nominal "
               "robot")
      ->needs(logs);
  app.add_option_function<double>(
         "--publish-rate", [&o](double hz) { o.publish_period_s = 1.0 / hz; },
         "With --logs: the controller's publish_rate (Hz), the interval its twist covariance is "
         "for (default: the encoder period)")
      ->check(PositiveNumber())
      ->needs(logs);
  app.add_option("--calibration-out", o.calibration_out,
                 "With --logs: write the calibration with its odometry covariance here");
  app.add_flag("--force", o.force, io::kForceFileHelp);
}

namespace {

// The overwrite rule (io/output_guard.h): --out never over its calibration or the data set;
// over the parameter file of the same node (a previous export) freely, over any other file only
// with --force.
void CheckOut(const ExportRos2ControlOptions& o) {
  if (o.out.empty()) return;
  std::string refusal = io::OutputFileRefusal(o.out, {o.calibration, o.logs});
  if (!refusal.empty()) throw UsageError(refusal);
  refusal =
      io::ParameterFileOverwriteRefusal(o.out, o.node_name.empty() ? o.controller : o.node_name);
  if (!refusal.empty() && !o.force) throw UsageError(refusal);
}

// --calibration-out like fit's --out: a calibration of the same robot is replaced.
void CheckCalibrationOut(const ExportRos2ControlOptions& o, const std::string& robot_name) {
  if (o.calibration_out.empty()) return;
  if (o.logs.empty()) {
    throw UsageError(
        "--calibration-out needs --logs (the covariance comes from the held-out runs)");
  }
  std::string refusal = io::OutputFileRefusal(o.calibration_out, {o.calibration, o.logs});
  if (!refusal.empty()) throw UsageError(refusal);
  refusal = io::OverwriteRefusal(o.calibration_out, robot_name);
  if (!refusal.empty() && !o.force) throw UsageError(refusal);
}

// The replay's verdict (WorseThanNominalError, exit 5, unless --allow-worse), its lines (on stdout
// beside a written file; in the YAML's comments either way: stdout stays YAML), the covariance keys
// and the calibration with its covariance (--calibration-out).
void AddReplay(const ExportRos2ControlOptions& o, const RobotModelPtr& exact,
               const Ros2ControlExport& e, std::string* text, std::string* parameters,
               std::string* calibration_text) {
  const ExportReplay replay =
      ReplayExport(o.logs, o.calibration, exact, e, o.publish_period_s);
  const std::string line = ReplayLine(o, replay);
  if (!o.out.empty()) std::printf("%s\n", line.c_str());
  if (const std::string refusal = replay.WorseRefusal(!e.notes.empty());
      !refusal.empty() && !o.allow_worse) {
    throw WorseThanNominalError(refusal);
  }
  *text += "# " + io::YamlCommentText(line) + "\n";
  for (const std::string& warning : replay.never_worse.warnings) {
    if (!o.out.empty()) std::printf("warning: %s\n", warning.c_str());
    *text += "# warning: " + io::YamlCommentText(warning) + "\n";
  }
  const std::string covariance = CovarianceLine(replay.exported_covariance);
  if (!o.out.empty()) std::printf("%s\n", covariance.c_str());
  *text += "# " + covariance + " (docs/ros2.md)\n";
  *parameters += Ros2CovarianceParameters(o.controller, replay.exported_covariance);
  if (!o.calibration_out.empty()) {
    *calibration_text = CalibrationWithCovariance(o.calibration, replay.exact_covariance);
  }
}

}  // namespace

int RunExportRos2ControlCommand(const ExportRos2ControlOptions& o) {
  return RunReportingErrors("fitcal export ros2-control", [&]() -> int {
    CheckOut(o);
    CheckControllerDistro(o.controller, o.ros_distro);
    // The calibration is read once: the export and the replay share its model.
    const RobotModelPtr calibrated = ReadRobotModelFile(o.calibration);
    const Ros2ControlExport e = ExportRos2Control(calibrated, o.calibration, o.controller,
                                                  o.node_name, o.joints, o.ros_distro);
    std::string text = "# " + o.controller + " parameters (ros2_controllers, ROS 2 " +
                       o.ros_distro + ") from the fitcal calibration " +
                       io::YamlCommentText(o.calibration) + "\n";
    for (const std::string& note : e.notes) {
      text += "# not representable: " + io::YamlCommentText(note) + "\n";
    }
    CheckCalibrationOut(o, calibrated->robot().name);
    std::string parameters = e.parameters_yaml, calibration_text;
    if (!o.logs.empty()) AddReplay(o, calibrated, e, &text, &parameters, &calibration_text);
    text += parameters;
    // The notes after the verdict: a refusal is one line.
    for (const std::string& note : e.notes)
      std::cerr << "fitcal export ros2-control: note: " << note << "\n";
    if (o.out.empty()) {
      std::cout << text;
    } else {
      io::WriteFileAtomically(o.out, text);
    }
    if (!calibration_text.empty()) io::WriteFileAtomically(o.calibration_out, calibration_text);
    return 0;
  });
}

}  // namespace fitcal::tools
