#include "tools/export_ros2_control.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "fit/final_pose_errors.h"
#include "io/atomic_file.h"
#include "io/calibration_yaml.h"
#include "io/dataset.h"
#include "io/ros2_parameter_yaml.h"
#include "io/text_file.h"
#include "io/yaml_scalar.h"
#include "models/model_registry.h"
#include "models/mounted_model.h"
#include "odometry/aligned_run.h"
#include "odometry/effects.h"
#include "io/command_failure.h"
#include "tools/dataset_command.h"
#include "tools/output_guard.h"
#include "validation/everyday_driving.h"
#include "validation/never_worse.h"
#include "validation/odometry_covariance.h"
#include "validation/training_runs.h"

namespace fitcal::tools {
namespace {

using io::Ros2Double;

CalibratedRobot WithJoints(RobotModelPtr model, const std::vector<std::string>& joints) {
  CalibratedRobot c;
  c.model = std::move(model);
  const Robot& robot = c.robot();
  if (!joints.empty() && joints.size() != robot.channels.size()) {
    throw UsageError("--joints names " + std::to_string(joints.size()) + " joints; robot '" +
                     robot.name + "' has " + std::to_string(robot.channels.size()) + " channels");
  }
  for (std::size_t j = 0; j < robot.channels.size(); ++j) {
    c.joints.push_back(joints.empty() ? robot.channels[j].name : joints[j]);
  }
  return c;
}

// A controller as the registered models write it (ModelExtras::controllers): the distributions
// that ship it and, for each model that takes it, that model's writer.
struct ControllerEntry {
  std::string name;
  std::string distros;
  std::vector<std::pair<std::string, ControllerWriteFn>> writers;  // model name, writer
};

ControllerEntry FindController(const std::string& name) {
  ControllerEntry entry{name, "", {}};
  for (const ModelRegistration& m : RegisteredModels()) {
    for (const ControllerWriter& w : m.extras.controllers) {
      if (w.controller != name) continue;
      entry.distros = w.distros;
      entry.writers.emplace_back(m.name, w.write);
    }
  }
  if (entry.writers.empty()) {
    std::string known;
    for (const std::string& c : Ros2Controllers()) known += (known.empty() ? "" : ", ") + c;
    throw UsageError("unknown controller '" + name + "' (fitcal writes " + known + ")");
  }
  return entry;
}

bool InList(const std::string& list, const std::string& word) {
  return (" " + list + " ").find(" " + word + " ") != std::string::npos;
}

// The writer of `model`; nullptr when the controller does not take it.
const ControllerWriteFn* WriterFor(const ControllerEntry& e, const std::string& model) {
  for (const auto& [name, write] : e.writers) {
    if (name == model) return &write;
  }
  return nullptr;
}

// "omni3 omni": the models that take the controller, for the mismatch message.
std::string ModelsTaking(const ControllerEntry& e) {
  std::string out;
  for (const auto& writer : e.writers) out += (out.empty() ? "" : " ") + writer.first;
  return out;
}

void CheckDistro(const ControllerEntry& e, const std::string& distro) {
  const std::vector<std::string>& all = RosDistros();
  if (std::find(all.begin(), all.end(), distro) == all.end()) {
    std::string known;
    for (const std::string& d : all) known += (known.empty() ? "" : ", ") + d;
    throw UsageError("--ros-distro '" + distro + "' is not one of " + known);
  }
  if (!InList(e.distros, distro)) {
    throw UsageError(e.name + " is not in ROS 2 " + distro + " (it ships in " +
                     e.distros + ")");
  }
}

// The controller's parameters describe the base; a controller model that replaced the calibrated
// one (omni, mecanum) is replayed against the ground truth through the calibrated frame still
// (models/mounted_model.h), or its held-out check would compare the base with the sensor.
void KeepGroundTruthFrame(const CalibratedRobot& c, Ros2ControlExport* out) {
  const auto* mounted = dynamic_cast<const MountedModel*>(c.model.get());
  if (mounted == nullptr || out->model == c.model) return;
  const int k = mounted->MountIndex();
  const std::vector<double>& p = c.robot().nominal;
  const std::vector<Interval> bounds(c.robot().bounds.begin() + k, c.robot().bounds.end());
  out->model = std::make_shared<MountedModel>(out->model, GroundTruthFrame{p[k], p[k + 1], p[k + 2]},
                                              bounds);
  out->parameters.insert(out->parameters.end(), p.begin() + k, p.end());
}

}  // namespace

const std::vector<std::string>& RosDistros() {
  static const std::vector<std::string> names = {"humble", "jazzy", "rolling"};
  return names;
}

std::vector<std::string> Ros2Controllers() {
  std::set<std::string> names;
  for (const ModelRegistration& m : RegisteredModels()) {
    for (const ControllerWriter& w : m.extras.controllers) names.insert(w.controller);
  }
  return {names.begin(), names.end()};
}

Ros2ControlExport ExportRos2Control(const RobotModelPtr& calibrated,
                                    const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints,
                                    const std::string& ros_distro) {
  const ControllerEntry entry = FindController(controller);
  CheckDistro(entry, ros_distro);
  const CalibratedRobot c = WithJoints(calibrated, joints);
  const ControllerWriteFn* write = WriterFor(entry, c.robot().model);
  if (write == nullptr) {
    throw UsageError(calibration_path + ": robot model '" + c.robot().model + "' does not fit " +
                     controller + " (it takes model " + ModelsTaking(entry) + ")");
  }
  if (!c.robot().effects.empty()) {
    // Its parameters were fitted together with the effects, which the controller cannot apply:
    // alone they are worse than a calibration fitted without effects.
    std::string names;
    for (const effects::EffectValue& e : c.robot().effects) {
      names += (names.empty() ? "" : ", ") + std::string(effects::Info(e.id).name);
    }
    throw UsageError(calibration_path + ": the calibration carries effects (" + names + ") that " +
                     controller + " cannot apply; export a calibration fitted without effects");
  }
  Ros2ControlExport out;
  out.parameters_yaml =
      io::YamlScalar(node_name.empty() ? controller : node_name) + ":\n  ros__parameters:\n";
  try {
    (*write)(c, ros_distro, &out);
  } catch (const ControllerCannotDescribe& e) {
    throw UsageError(e.what());
  }
  KeepGroundTruthFrame(c, &out);
  return out;
}

Ros2ControlExport ExportRos2Control(const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints,
                                    const std::string& ros_distro) {
  CheckDistro(FindController(controller), ros_distro);
  return ExportRos2Control(ReadRobotModelFile(calibration_path), calibration_path, controller,
                           node_name, joints, ros_distro);
}

}  // namespace fitcal::tools

namespace fitcal::tools {

namespace {

// The held-out runs of a loaded data set (ExportHeldOutRuns); `held_out_logs` takes theirs.
std::vector<AlignedRun> HeldOutRuns(const std::string& calibration_path, io::Dataset data,
                                    std::string* which, std::vector<RunLog>* held_out_logs) {
  // The rule `report` uses (tools/report_command.cc, SplitForReport): the recorded training run
  // ids (and fingerprint) when this data set holds them, by repetition for older files.
  RecordedTraining recorded;
  if (const std::optional<io::CalibrationProvenance> p =
          io::ReadCalibrationProvenance(calibration_path)) {
    recorded.run_ids = p->training_run_ids;
    recorded.fingerprint = p->training_fingerprint;
    recorded.repetitions = p->training_repetitions;
  }
  TrainingSplit t = SplitAsRecorded(data.runs, AlignRuns(data.runs), recorded);
  // As `report` refuses it (exit 2): runs the calibration was fitted on cannot judge it, and the
  // covariance of its own residuals there would be the fit's, smaller than the robot will see.
  if (t.split.validation.empty()) {
    throw UsageError("every run of " + data.directory +
                     " trained the calibration; nothing held out to replay it on or to take "
                     "the odometry covariance from (--logs a data set with runs it did not fit)");
  }
  *which = t.how == "none" ? "(none of them trained the calibration)"
                           : "held out from the calibration";
  std::vector<AlignedRun> runs = std::move(t.split.validation);
  if (held_out_logs != nullptr) {
    std::set<std::string> ids;
    for (const AlignedRun& r : runs) ids.insert(r.id);
    for (RunLog& r : data.runs) {
      if (ids.count(r.id) > 0) held_out_logs->push_back(std::move(r));
    }
  }
  return runs;
}

}  // namespace

std::vector<AlignedRun> ExportHeldOutRuns(const std::string& calibration_path,
                                          const std::string& logs, const Robot& robot,
                                          std::string* which,
                                          std::vector<RunLog>* held_out_logs) {
  return HeldOutRuns(calibration_path, io::LoadDataset(io::ReadDatasetIndex(logs), robot), which,
                     held_out_logs);
}

namespace {

// The exported parameters replayed on the held-out runs beside the nominal robot and the exact
// calibration: CF (Palacin Eq. 14) of each, and the odometry covariance of both calibrations.
struct Replay {
  std::size_t runs = 0;
  std::string which;
  double cf_nominal = 0.0, cf_exact = 0.0, cf_exported = 0.0;
  OdometryCovariance exported_covariance, exact_covariance;
  // The never-worse judgement of the exported parameters against the nominal (validation/
  // never_worse.h, the rule fit applies): worse on a kind of run, in drift or ATE, beyond the
  // runs' scatter refuses; what only warns is said beside the replay line.
  NeverWorseSaid never_worse;
  bool Worse() const { return cf_exported > cf_nominal || !never_worse.refusals.empty(); }
};

// The never-worse judgement of the exported parameters against the nominal robot on `runs`.
NeverWorseSaid ExportNeverWorse(const RobotModelInterface& nominal,
                                const Ros2ControlExport& exported,
                                const std::vector<AlignedRun>& runs) {
  const std::vector<const GroundTruthTrack*> tracks = TracksOf(runs);
  const std::vector<double> lengths = EverydayDriftLengths();
  return SayNeverWorse(
      "the exported parameters",
      JudgeNeverWorse(runs,
                      EvaluateEverydayDriving(nominal, nominal.robot().nominal, {}, runs, tracks,
                                              lengths),
                      EvaluateEverydayDriving(*exported.model, exported.parameters, {}, runs,
                                              tracks, lengths)));
}

// `exact` is the calibration as read, `exported` what the controller computes from the export;
// the data set is read once.
Replay ReplayOnHeldOutRuns(const ExportRos2ControlOptions& o, const RobotModelPtr& exact,
                           const Ros2ControlExport& exported) {
  const io::DatasetIndex index = io::ReadDatasetIndex(o.logs);
  const RobotModelPtr nominal = ReadRobotModelFile(index.robot_path);
  if (nominal->robot().model != exact->robot().model) {
    throw UsageError(o.logs + ": its robot is a " + nominal->robot().model +
                     ", the calibration a " + exact->robot().model);
  }
  Replay r;
  std::vector<RunLog> logs;
  const std::vector<AlignedRun> runs = HeldOutRuns(
      o.calibration, io::LoadDataset(index, exact->robot()), &r.which, &logs);
  r.runs = runs.size();
  r.cf_nominal = EvaluateFinalPoseErrors(*nominal, nominal->robot().nominal, runs).cf;
  r.cf_exact = EvaluateFinalPoseErrors(*exact, exact->robot().nominal, runs).cf;
  r.cf_exported = EvaluateFinalPoseErrors(*exported.model, exported.parameters, runs).cf;
  r.never_worse = ExportNeverWorse(*nominal, exported, runs);
  const auto covariance = [&](const RobotModelInterface& model, const std::vector<double>& p) {
    return EstimateOdometryCovariance(model, p, logs, o.publish_period_s);
  };
  r.exported_covariance = covariance(*exported.model, exported.parameters);
  r.exact_covariance = covariance(*exact, exact->robot().nominal);
  return r;
}

std::string ReplayLine(const ExportRos2ControlOptions& o, const Replay& r) {
  char text[400];
  std::snprintf(text, sizeof text,
                "CF (Palacin Eq. 14, m and rad) over %zu runs of %s %s: nominal robot %.6f, "
                "exact calibration %.6f, these parameters %.6f (%+.1f %% vs exact)",
                r.runs, o.logs.c_str(), r.which.c_str(), r.cf_nominal, r.cf_exact, r.cf_exported,
                100.0 * (r.cf_exported / r.cf_exact - 1.0));
  return text;
}

// Variance written for the axes planar odometry does not measure (z, roll, pitch): large, so
// that an EKF that fuses them anyway gives them no weight (robot_localization's two_d_mode
// ignores them).
constexpr double kUnmeasuredVariance = 1e6;

std::string Diagonal(const std::array<double, 3>& planar) {
  return "[" + Ros2Double(planar[0]) + ", " + Ros2Double(planar[1]) + ", " + Ros2Double(kUnmeasuredVariance) + ", " +
         Ros2Double(kUnmeasuredVariance) + ", " + Ros2Double(kUnmeasuredVariance) + ", " + Ros2Double(planar[2]) + "]";
}

}  // namespace

std::string Ros2CovarianceParameters(const std::string& controller, const OdometryCovariance& c) {
  if (controller == "omni_wheel_drive_controller") {
    return "    diagonal_covariance:\n      pose: " + Diagonal(c.pose_variance_1m) +
           "\n      twist: " + Diagonal(c.twist_variance) + "\n";
  }
  return "    pose_covariance_diagonal: " + Diagonal(c.pose_variance_1m) +
         "\n    twist_covariance_diagonal: " + Diagonal(c.twist_variance) + "\n";
}

namespace {

std::string CovarianceLine(const OdometryCovariance& c) {
  char text[600];
  std::snprintf(text, sizeof text,
                "odometry covariance from %zu held-out runs (%zu windows; twist per message of %.4g s): twist sigma "
                "vx %.4g m/s, vy %.4g m/s, omega %.4g rad/s; pose sigma after 1 m x %.4g m, "
                "y %.4g m, theta %.4g rad, growing as d^%.2f, d^%.2f, d^%.2f; ground truth's own "
                "noise removed: %.3g m, %.3g m, %.3g rad",
                c.runs, c.windows, c.interval_s, std::sqrt(c.twist_variance[0]),
                std::sqrt(c.twist_variance[1]), std::sqrt(c.twist_variance[2]),
                std::sqrt(c.pose_variance_1m[0]), std::sqrt(c.pose_variance_1m[1]),
                std::sqrt(c.pose_variance_1m[2]), 0.5 * c.pose_growth_exponent[0],
                0.5 * c.pose_growth_exponent[1], 0.5 * c.pose_growth_exponent[2],
                std::sqrt(c.ground_truth_variance[0]), std::sqrt(c.ground_truth_variance[1]),
                std::sqrt(c.ground_truth_variance[2]));
  return text;
}

// The calibration file with `calibration.odometry_covariance` (one flow-style line right after
// `calibration:`, replacing an earlier one): the file stays a robot YAML every reader takes.
std::string CalibrationWithCovariance(const std::string& path, const OdometryCovariance& c) {
  std::istringstream in(io::ReadTextFile(path));
  std::string out, line;
  bool found = false;
  while (std::getline(in, line)) {
    if (line.rfind("  odometry_covariance:", 0) == 0) continue;
    out += line + "\n";
    if (line == "calibration:") {
      found = true;
      const auto list = [](const std::array<double, 3>& v) {
        return "[" + Ros2Double(v[0]) + ", " + Ros2Double(v[1]) + ", " + Ros2Double(v[2]) + "]";
      };
      out += "  odometry_covariance: {interval_s: " + Ros2Double(c.interval_s) +
             ", held_out_runs: " + std::to_string(c.runs) + ", windows: " +
             std::to_string(c.windows) + ", twist_variance: " + list(c.twist_variance) +
             ", pose_variance_1m: " + list(c.pose_variance_1m) +
             ", pose_growth_exponent: " + list(c.pose_growth_exponent) +
             ", ground_truth_variance: " + list(c.ground_truth_variance) + "}\n";
    }
  }
  if (!found) {
    throw UsageError(path +
                     ": no calibration: block (a calibration written by fit) "
                     "to hold the odometry covariance (--calibration-out)");
  }
  return out;
}

}  // namespace

void AddExportRos2ControlOptions(CLI::App& app, ExportRos2ControlOptions& o) {
  app.add_option("--calibration", o.calibration, "Calibrated robot YAML (from fit)")
      ->required()
      ->check(CLI::ExistingFile);
  std::string names;
  for (const std::string& c : Ros2Controllers()) names += (names.empty() ? "" : ", ") + c;
  app.add_option("--controller", o.controller, "One of " + names)->required();
  app.add_option("--node-name", o.node_name, "Top-level key (default: the controller's name)");
  app.add_option("--joints", o.joints,
                 "URDF joint names in the robot's channel order (default: the channel names)")
      ->delimiter(',');
  app.add_option("--out", o.out, "File to write (atomically; default: stdout)");
  app.add_option("--logs", o.logs,
                 "Data set: replay the exported parameters on its held-out runs beside the "
                 "nominal robot and the exact calibration; refuse them if worse than nominal")
      ->check(CLI::ExistingDirectory);
  std::string distros;
  for (const std::string& d : RosDistros()) distros += (distros.empty() ? "" : "|") + d;
  app.add_option("--ros-distro", o.ros_distro,
                 "ROS 2 distribution (" + distros + "): only the keys it declares are written")
      ->capture_default_str();
  app.add_flag("--allow-worse", o.allow_worse,
               "Write the parameters even when they replay worse than the nominal robot");
  app.add_option_function<double>(
         "--publish-rate", [&o](double hz) { o.publish_period_s = 1.0 / hz; },
         "With --logs: the controller's publish_rate (Hz), the interval its twist covariance is "
         "for (default: the encoder period)")
      ->check(CLI::PositiveNumber);
  app.add_option("--calibration-out", o.calibration_out,
                 "With --logs: write the calibration with its odometry covariance here");
  app.add_flag("--force", o.force, kForceFileHelp);
}

namespace {

// The overwrite rule (tools/output_guard.h): --out never over its calibration or the data set;
// over the parameter file of the same node (a previous export) freely, over any other file only
// with --force.
void CheckOut(const ExportRos2ControlOptions& o) {
  if (o.out.empty()) return;
  std::string refusal = OutputFileRefusal(o.out, {o.calibration, o.logs});
  if (!refusal.empty()) throw UsageError(refusal);
  refusal = ParameterFileOverwriteRefusal(o.out, o.node_name.empty() ? o.controller : o.node_name);
  if (!refusal.empty() && !o.force) throw UsageError(refusal);
}

// --calibration-out like fit's --out: a calibration of the same robot is replaced.
void CheckCalibrationOut(const ExportRos2ControlOptions& o, const std::string& robot_name) {
  if (o.calibration_out.empty()) return;
  if (o.logs.empty()) {
    throw UsageError(
        "--calibration-out needs --logs (the covariance comes from "
        "the held-out runs)");
  }
  std::string refusal = OutputFileRefusal(o.calibration_out, {o.calibration, o.logs});
  if (!refusal.empty()) throw UsageError(refusal);
  refusal = OverwriteRefusal(o.calibration_out, robot_name);
  if (!refusal.empty() && !o.force) throw UsageError(refusal);
}

// The replay's verdict (WorseThanNominalError, exit 5, unless --allow-worse), its lines (on stdout
// beside a written file; in the YAML's comments either way: stdout stays YAML), the covariance keys
// and the calibration with its covariance (--calibration-out).
void AddReplay(const ExportRos2ControlOptions& o, const RobotModelPtr& exact,
               const Ros2ControlExport& e, std::string* text, std::string* parameters,
               std::string* calibration_text) {
  const Replay replay = ReplayOnHeldOutRuns(o, exact, e);
  const std::string line = ReplayLine(o, replay);
  if (!o.out.empty()) std::printf("%s\n", line.c_str());
  if (replay.Worse() && !o.allow_worse) {
    char text_worse[300];
    std::snprintf(text_worse, sizeof text_worse, "CF %.6f > %.6f on %zu runs",
                  replay.cf_exported, replay.cf_nominal, replay.runs);
    const std::string what = replay.cf_exported > replay.cf_nominal
                                 ? std::string(text_worse)
                                 : replay.never_worse.refusals.front();
    throw WorseThanNominalError("these parameters replay worse than the nominal robot (" + what +
                                "); nothing written (--allow-worse writes them" +
                                (e.notes.empty() ? ""
                                                 : ", with notes on what the controller leaves "
                                                   "out: apply that first, e.g. a steering "
                                                   "offset") +
                                ")");
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
    CheckDistro(FindController(o.controller), o.ros_distro);
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
