#include "interchange/ros2/controller_export.h"

#include <algorithm>
#include <optional>
#include <set>
#include <sstream>

#include "fit/final_pose_errors.h"
#include "io/calibration_yaml.h"
#include "io/command_failure.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/ros2_parameter_yaml.h"
#include "io/text_file.h"
#include "io/yaml_scalar.h"
#include "models/model_registry.h"
#include "models/mounted_model.h"
#include "odometry/effects.h"
#include "odometry/text_format.h"
#include "validation/calibration_match.h"
#include "validation/everyday_driving.h"
#include "validation/training_runs.h"

namespace fitcal {
namespace {

using io::Ros2Double;

CalibratedRobot WithJoints(RobotModelPtr model, const std::vector<std::string>& joints) {
  CalibratedRobot c;
  c.model = std::move(model);
  const Robot& robot = c.robot();
  c.joints = io::ChannelJointNames(robot, joints);
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
    throw UsageError("unknown controller '" + name + "' (fitcal writes " +
                     io::Joined(Ros2Controllers(), ", ") + ")");
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
  return io::Joined(e.writers, " ", [](const auto& writer) { return writer.first; });
}

void CheckDistro(const ControllerEntry& e, const std::string& distro) {
  const std::vector<std::string>& all = RosDistros();
  if (std::find(all.begin(), all.end(), distro) == all.end()) {
    throw UsageError("--ros-distro '" + distro + "' is not one of " + io::Joined(all, ", "));
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
  out->model = std::make_shared<MountedModel>(out->model,
                                              GroundTruthFrame{p[k], p[k + 1], p[k + 2]}, bounds);
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

void CheckControllerDistro(const std::string& controller, const std::string& ros_distro) {
  CheckDistro(FindController(controller), ros_distro);
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
    const std::string names = io::Joined(
        c.robot().effects, ", ",
        [](const effects::EffectValue& e) { return std::string(effects::Info(e.id).name); });
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

namespace {

// The runs of a loaded data set that validate `calibration_path`: those it did not train on (by
// recorded run id, as `report` splits; every run when it records none); `*which` says which.
// Throws UsageError (exit 2, as `report`) when it trained on every run. `held_out_logs`, when
// given, receives the same runs as loaded (ground-truth tracks included).
std::vector<AlignedRun> HeldOutRuns(const std::string& calibration_path, io::Dataset data,
                                    std::string* which, std::vector<RunLog>* held_out_logs) {
  // The rule `report` uses (cli/report_command.cc, SplitForReport): the recorded training run
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

}  // namespace

ExportReplay ReplayExport(const std::string& logs, const std::string& calibration_path,
                          const RobotModelPtr& exact, const Ros2ControlExport& exported,
                          double publish_period_s) {
  const io::DatasetIndex index = io::ReadDatasetIndex(logs);
  const RobotModelPtr nominal = ReadRobotModelFile(index.robot_path);
  if (nominal->robot().model != exact->robot().model) {
    throw UsageError(logs + ": its robot is a " + nominal->robot().model +
                     ", the calibration a " + exact->robot().model);
  }
  if (const std::string refusal = ChannelOrderRefusal(exact->robot(), nominal->robot());
      !refusal.empty()) {
    throw io::InputError(io::InputErrorKind::kBadValue, calibration_path, 0, refusal);
  }
  ExportReplay r;
  std::vector<RunLog> held_out_logs;
  const std::vector<AlignedRun> runs = HeldOutRuns(
      calibration_path, io::LoadDataset(index, exact->robot()), &r.which, &held_out_logs);
  r.runs = runs.size();
  r.cf_nominal = EvaluateFinalPoseErrors(*nominal, nominal->robot().nominal, runs).cf;
  r.cf_exact = EvaluateFinalPoseErrors(*exact, exact->robot().nominal, runs).cf;
  r.cf_exported = EvaluateFinalPoseErrors(*exported.model, exported.parameters, runs).cf;
  r.never_worse = ExportNeverWorse(*nominal, exported, runs);
  const auto covariance = [&](const RobotModelInterface& model, const std::vector<double>& p) {
    return EstimateOdometryCovariance(model, p, held_out_logs, publish_period_s);
  };
  r.exported_covariance = covariance(*exported.model, exported.parameters);
  r.exact_covariance = covariance(*exact, exact->robot().nominal);
  return r;
}

std::string ExportReplay::WorseRefusal(bool has_notes) const {
  if (!Worse()) return "";
  const std::string what = cf_exported > cf_nominal ? StrFormat("CF %.6f > %.6f on %zu runs",
                                                                cf_exported, cf_nominal, runs)
                                                    : never_worse.refusals.front();
  return "these parameters replay worse than the nominal robot (" + what +
         "); nothing written (--allow-worse writes them" +
         (has_notes ? ", with notes on what the controller leaves out: apply that first, e.g. a "
                      "steering offset"
                    : "") +
         ")";
}

namespace {

// Variance written for the axes planar odometry does not measure (z, roll, pitch): large, so
// that an EKF that fuses them anyway gives them no weight (robot_localization's two_d_mode
// ignores them).
constexpr double kUnmeasuredVariance = 1e6;

std::string Diagonal(const std::array<double, 3>& planar) {
  return "[" + Ros2Double(planar[0]) + ", " + Ros2Double(planar[1]) + ", " +
         Ros2Double(kUnmeasuredVariance) + ", " + Ros2Double(kUnmeasuredVariance) + ", " +
         Ros2Double(kUnmeasuredVariance) + ", " + Ros2Double(planar[2]) + "]";
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

}  // namespace fitcal
