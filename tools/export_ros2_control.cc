#include "tools/export_ros2_control.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "fit/final_pose_errors.h"
#include "io/atomic_file.h"
#include "io/calibration_yaml.h"
#include "io/dataset.h"
#include "io/text_file.h"
#include "io/yaml_scalar.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "models/mounted_model.h"
#include "models/omni/omni_model.h"
#include "models/tricycle/tricycle_kinematics.h"
#include "odometry/aligned_run.h"
#include "odometry/effects.h"
#include "tools/command_failure.h"
#include "tools/dataset_command.h"
#include "tools/output_guard.h"
#include "validation/everyday_driving.h"
#include "validation/never_worse.h"
#include "validation/odometry_covariance.h"
#include "validation/training_runs.h"

namespace fitcal::tools {
namespace {

constexpr double kDeg = M_PI / 180.0;
// Fixed geometry (drive and roller angles) is written by fitcal with 10 significant digits: a
// difference below this is the same angle.
constexpr double kSameAngleRad = 1e-6;

// A double as ROS 2 parameter YAML must hold it: with a decimal point, else rclcpp types it as an
// integer and a double parameter refuses it.
std::string Num(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.12g", v);
  std::string s = text;
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

// Joint names double-quoted and escaped (io/yaml_scalar.h): a quote in a URDF name stays YAML.
std::string Quoted(const std::string& s) { return io::YamlDoubleQuoted(s); }

std::string NameList(const std::vector<std::string>& names) {
  std::string out = "[";
  for (std::size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + Quoted(names[i]);
  return out + "]";
}

// A value as the controller reads it back from the YAML Num wrote (12 significant digits): the
// replay runs the parameters the controller will run.
double AsWritten(double v) { return std::strtod(Num(v).c_str(), nullptr); }

// The calibrated robot, read once through the model registry, and the joint of each channel.
struct Calibrated {
  RobotModelPtr model;
  std::vector<std::string> joints;  // robot channel order
  const Robot& robot() const { return model->robot(); }
  // The calibrated value of a parameter, found by name in the model's parameter table.
  int Index(const std::string& name) const { return RequireParameterIndex(robot(), name); }
  double Value(const std::string& name) const { return robot().nominal[Index(name)]; }
  const std::string& ChannelName(int i) const { return robot().channels[i].name; }
};

Calibrated WithJoints(RobotModelPtr model, const std::vector<std::string>& joints) {
  Calibrated c;
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

// The wheels of an omni / omni3 robot at its calibrated values (models/omni/omni_model.h).
std::vector<OmniWheel> OmniGeometry(const Calibrated& c) {
  const std::optional<std::vector<OmniWheel>> wheels =
      OmniWheelsOf(*c.model, c.robot().nominal);
  if (!wheels) throw std::logic_error("robot '" + c.robot().name + "' has no omni wheels");
  return *wheels;
}

double Mean(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

// "one value for all wheels" note when the values differ.
void NoteSpread(const std::vector<double>& v, const std::string& what, const std::string& key,
                double scale, const char* unit, std::vector<std::string>* notes) {
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  if (*hi - *lo <= 1e-12 * std::abs(*hi)) return;
  char text[256];
  std::snprintf(text, sizeof text,
                "%s takes one %s: the calibrated %.6g..%.6g %s are written as "
                "their mean %.6g %s",
                key.c_str(), what.c_str(), *lo * scale, *hi * scale, unit, Mean(v) * scale, unit);
  notes->push_back(text);
}

void DiffDriveParameters(const Calibrated& c, const std::string& distro, Ros2ControlExport* out) {
  const int right = DiffDriveRightChannel(*c.model), left = 1 - right;
  const int k_right = c.Index("r_" + c.ChannelName(right));
  const int k_left = c.Index("r_" + c.ChannelName(left));
  const int k_separation = c.Index("wheel_separation");
  const std::vector<double>& p = c.robot().nominal;
  const double radius = 0.5 * (p[k_right] + p[k_left]);
  out->parameters_yaml +=
      "    left_wheel_names: " + NameList({c.joints[left]}) +
      "\n    right_wheel_names: " + NameList({c.joints[right]}) +
      // humble declares wheels_per_side (and overwrites it with the names' count); jazzy and
      // rolling no longer declare it, and an undeclared key is ignored there.
      (distro == "humble" ? "\n    wheels_per_side: 1" : "") + "\n    wheel_separation: " +
      Num(p[k_separation]) + "\n    wheel_radius: " + Num(radius) +
      "\n    wheel_separation_multiplier: 1.0" +
      "\n    left_wheel_radius_multiplier: " + Num(p[k_left] / radius) +
      "\n    right_wheel_radius_multiplier: " + Num(p[k_right] / radius) + "\n";
  // The controller's wheels: wheel_radius times each side's multiplier, the separation times 1.
  out->model = c.model;
  out->parameters = p;
  out->parameters[k_right] = AsWritten(radius) * AsWritten(p[k_right] / radius);
  out->parameters[k_left] = AsWritten(radius) * AsWritten(p[k_left] / radius);
  out->parameters[k_separation] = AsWritten(p[k_separation]);
}

// ros2_controllers' mecanum layout (its odometry: vx = r/4 (fl + rl + rr + fr), vy = r/4 (-fl +
// rl - rr + fr), omega = r / (4 (lx + ly)) (-fl - rl + rr + fr)): wheels driven straight ahead,
// rollers -45 deg on front-left and rear-right, +45 deg on front-right and rear-left.
struct MecanumCorner {
  const char* key;  // <key>_wheel_command_joint_name
  double sign_x, sign_y, roller_deg;
};
constexpr MecanumCorner kCorners[] = {{"front_left", 1, 1, -45},
                                      {"front_right", 1, -1, 45},
                                      {"rear_left", -1, 1, 45},
                                      {"rear_right", -1, -1, -45}};

// The channel at each corner (kCorners order); std::invalid_argument when the layout differs.
std::vector<int> MecanumCorners(const std::vector<OmniWheel>& wheels, const Robot& robot) {
  std::vector<int> at(4, -1);
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    const double x = wheels[i].distance_m * std::cos(wheels[i].angle_rad);
    const double y = wheels[i].distance_m * std::sin(wheels[i].angle_rad);
    for (int k = 0; k < 4; ++k) {
      if (x * kCorners[k].sign_x > 0 && y * kCorners[k].sign_y > 0) {
        const bool layout =
            std::abs(WrapAngle(wheels[i].drive_angle_rad)) < 15.0 * kDeg &&
            std::abs(wheels[i].roller_angle_rad - kCorners[k].roller_deg * kDeg) < kSameAngleRad;
        if (!layout || at[k] >= 0) {
          throw UsageError(
              "wheel '" + robot.channels[i].name + "' (" + kCorners[k].key +
              ") is not in mecanum_drive_controller's layout (driven straight ahead, rollers -45 "
              "deg front-left/rear-right, +45 deg front-right/rear-left, one wheel per corner)");
        }
        at[k] = static_cast<int>(i);
      }
    }
  }
  for (int k = 0; k < 4; ++k) {
    if (at[k] < 0) {
      throw UsageError(std::string("no wheel at the ") + kCorners[k].key +
                       " corner: not mecanum_drive_controller's layout");
    }
  }
  return at;
}

// Bounds of a robot built from a controller's values: its values lie inside (the replay never
// fits it).
OmniBounds ControllerBounds(double distance_m, double radius_m) {
  return {{0.5 * distance_m, 2 * distance_m}, {0.5 * radius_m, 2 * radius_m},
          {DegToRad(-2.0), DegToRad(2.0)}};
}

// What mecanum_drive_controller computes: its layout with one radius and lx = ly (any point with
// |x| + |y| = lx + ly gives the controller's yaw row).
RobotModelPtr MecanumKinematics(const Calibrated& c, const std::vector<int>& corner,
                                double radius_m, double sum_m) {
  const double distance_m = AsWritten(sum_m) / std::sqrt(2.0);
  std::vector<OmniWheel> wheels(4);
  for (int k = 0; k < 4; ++k) {
    wheels[corner[k]] = {c.ChannelName(corner[k]), distance_m,
                         std::atan2(kCorners[k].sign_y, kCorners[k].sign_x), AsWritten(radius_m),
                         0.0, DegToRad(kCorners[k].roller_deg)};
  }
  return MakeOmniModel(c.robot().name, wheels, ControllerBounds(distance_m, AsWritten(radius_m)));
}

void MecanumParameters(const Calibrated& c, const std::string&, Ros2ControlExport* out) {
  if (c.robot().model != "omni" || c.robot().NumChannels() != 4) {
    throw UsageError("mecanum_drive_controller takes an omni robot of 4 mecanum wheels");
  }
  const std::vector<OmniWheel> wheels = OmniGeometry(c);
  const std::vector<int> corner = MecanumCorners(wheels, c.robot());
  std::vector<double> radii, sums, drives;
  for (const OmniWheel& w : wheels) {
    radii.push_back(w.radius_m);
    sums.push_back(std::abs(w.distance_m * std::cos(w.angle_rad)) +
                   std::abs(w.distance_m * std::sin(w.angle_rad)));
    drives.push_back(std::abs(WrapAngle(w.drive_angle_rad)));
  }
  NoteSpread(radii, "radius", "kinematics.wheels_radius", 1.0, "m", &out->notes);
  NoteSpread(sums, "lx + ly", "kinematics.sum_of_robot_center_projection_on_X_Y_axis", 1.0, "m",
             &out->notes);
  const double worst_drive = *std::max_element(drives.begin(), drives.end());
  if (worst_drive > kSameAngleRad) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "mecanum_drive_controller drives every wheel straight ahead: "
                  "calibrated drive directions up to %.4g deg off it are written as 0",
                  worst_drive / kDeg);
    out->notes.push_back(text);
  }
  for (int k = 0; k < 4; ++k) {
    out->parameters_yaml += std::string("    ") + kCorners[k].key +
                            "_wheel_command_joint_name: " + Quoted(c.joints[corner[k]]) + "\n";
  }
  out->parameters_yaml += "    kinematics:\n      wheels_radius: " + Num(Mean(radii)) +
                          "\n      sum_of_robot_center_projection_on_X_Y_axis: " +
                          Num(Mean(sums)) + "\n";
  out->model = MecanumKinematics(c, corner, Mean(radii), Mean(sums));
  out->parameters = out->model->robot().nominal;
}

// Which way a positive wheel rate pushes the robot: +1 counter-clockwise (tangential drive, the
// fitcal default), -1 clockwise (omni_wheel_drive_controller's convention).
int OmniDriveSense(const std::vector<OmniWheel>& wheels, const Robot& robot) {
  int sense = 0;
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    const double offset = WrapAngle(wheels[i].drive_angle_rad - wheels[i].angle_rad);
    const int s = std::abs(offset - M_PI / 2) < kSameAngleRad   ? 1
                  : std::abs(offset + M_PI / 2) < kSameAngleRad ? -1
                                                                : 0;
    if (s == 0 || (sense != 0 && s != sense) || std::abs(wheels[i].roller_angle_rad) > kSameAngleRad) {
      throw UsageError("wheel '" + robot.channels[i].name +
                       "' is not an omni wheel driven tangentially like the others: "
                       "omni_wheel_drive_controller cannot describe it");
    }
    sense = s;
  }
  return sense;
}

// The wheels in omni_wheel_drive_controller's order: anticlockwise from the one nearest the x
// axis; returns the order and the offset (circular mean of angle_j - 2 pi j / n).
std::vector<int> OmniOrder(const std::vector<OmniWheel>& wheels, double* offset_rad) {
  const int n = static_cast<int>(wheels.size());
  int first = 0;
  for (int i = 1; i < n; ++i) {
    if (std::abs(WrapAngle(wheels[i].angle_rad)) < std::abs(WrapAngle(wheels[first].angle_rad))) {
      first = i;
    }
  }
  const auto ccw_from_first = [&](int i) {
    const double a = WrapAngle(wheels[i].angle_rad - wheels[first].angle_rad);
    return a < 0 ? a + 2 * M_PI : a;
  };
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return ccw_from_first(a) < ccw_from_first(b); });
  double s = 0.0, c = 0.0;
  for (int j = 0; j < n; ++j) {
    const double a = wheels[order[j]].angle_rad - 2 * M_PI * j / n;
    s += std::sin(a);
    c += std::cos(a);
  }
  *offset_rad = std::atan2(s, c);
  return order;
}

// What omni_wheel_drive_controller computes: one distance, one radius, the wheels equally spaced
// from the offset in `order`, each driven as the calibrated ones (sense). An `omni` robot gets a
// model of these wheels; omni3 (tangential wheels by construction) its own model at these values.
void OmniWheelKinematics(const Calibrated& c, const std::vector<int>& order, double offset_rad,
                         double distance_m, double radius_m, int sense, Ros2ControlExport* out) {
  const int n = static_cast<int>(order.size());
  std::vector<OmniWheel> wheels(n);
  for (int j = 0; j < n; ++j) {
    const double angle = AsWritten(offset_rad) + 2 * M_PI * j / n;
    wheels[order[j]] = {c.ChannelName(order[j]), AsWritten(distance_m), angle,
                        AsWritten(radius_m), angle + sense * M_PI / 2, 0.0};
  }
  if (c.robot().model == "omni") {
    out->model = MakeOmniModel(c.robot().name, wheels,
                               ControllerBounds(AsWritten(distance_m), AsWritten(radius_m)));
    out->parameters = out->model->robot().nominal;
    return;
  }
  out->model = c.model;
  out->parameters = c.robot().nominal;
  for (const OmniWheel& w : wheels) {
    out->parameters[c.Index("R_" + w.name)] = w.distance_m;
    out->parameters[c.Index("r_" + w.name)] = w.radius_m;
    out->parameters[c.Index("delta_" + w.name)] = w.angle_rad;
  }
}

void OmniWheelParameters(const Calibrated& c, const std::string&, Ros2ControlExport* out) {
  if (c.robot().model != "omni3" && c.robot().model != "omni") {
    throw UsageError("omni_wheel_drive_controller takes an omni3 or omni robot");
  }
  const std::vector<OmniWheel> wheels = OmniGeometry(c);
  const int sense = OmniDriveSense(wheels, c.robot());
  double offset = 0.0;
  const std::vector<int> order = OmniOrder(wheels, &offset);
  const int n = static_cast<int>(wheels.size());
  std::vector<double> radii, distances;
  double worst = 0.0;
  std::vector<std::string> names;
  for (int j = 0; j < n; ++j) {
    const OmniWheel& w = wheels[order[j]];
    radii.push_back(w.radius_m);
    distances.push_back(w.distance_m);
    worst = std::max(worst, std::abs(WrapAngle(w.angle_rad - offset - 2 * M_PI * j / n)));
    names.push_back(c.joints[order[j]]);
  }
  NoteSpread(radii, "radius", "wheel_radius", 1.0, "m", &out->notes);
  NoteSpread(distances, "distance", "robot_radius", 1.0, "m", &out->notes);
  if (worst > kSameAngleRad) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "omni_wheel_drive_controller spaces the wheels equally (%.4g "
                  "deg apart): the calibrated wheel angles are up to %.4g deg off that",
                  360.0 / n, worst / kDeg);
    out->notes.push_back(text);
  }
  if (sense > 0) {
    out->notes.push_back(
        "omni_wheel_drive_controller counts a wheel positive when it turns the robot clockwise "
        "(w r = sin(a) vx - cos(a) vy - R omega), this robot's wheels counter-clockwise: invert "
        "the wheel joints' axes in the URDF (or their sign in the hardware interface)");
  }
  out->parameters_yaml += "    wheel_names: " + NameList(names) +
                          "\n    wheel_offset: " + Num(offset) +
                          "\n    robot_radius: " + Num(Mean(distances)) +
                          "\n    wheel_radius: " + Num(Mean(radii)) + "\n";
  OmniWheelKinematics(c, order, offset, Mean(distances), Mean(radii), sense, out);
}

void TricycleParameters(const Calibrated& c, const std::string&, Ros2ControlExport* out) {
  using K = TricycleKinematics;
  const std::string& traction = c.joints[K::kTractionChannel];
  const std::string& steering = c.joints[K::kSteeringChannel];
  const int k_radius = c.Index("r_" + c.ChannelName(K::kTractionChannel));
  const int k_wheelbase = c.Index("wheelbase"), k_offset = c.Index("steering_offset");
  const std::vector<double>& p = c.robot().nominal;
  const double offset_rad = p[k_offset];
  if (offset_rad != 0.0) {
    // models/tricycle/tricycle_kinematics.h: true steering = measured + phi_0. The controller
    // reads the steering joint's state as the true angle, so the joint must report phi_0 more:
    // ros2_control's SimpleTransmission computes joint = actuator / reduction + offset, which
    // also shifts the commands the same way.
    char text[400];
    std::snprintf(text, sizeof text,
                  "tricycle_controller has no steering offset: add %+.9g rad (%+.6f deg) to "
                  "the steering joint '%s' position (true steering = measured %+.6f deg), e.g. "
                  "<offset>%.9g</offset> in its SimpleTransmission <joint> in the URDF "
                  "(joint = actuator / reduction + offset), or zero the steering encoder there",
                  offset_rad, offset_rad / kDeg, steering.c_str(), offset_rad / kDeg, offset_rad);
    out->notes.push_back(text);
  }
  out->parameters_yaml += "    traction_joint_name: " + Quoted(traction) +
                          "\n    steering_joint_name: " + Quoted(steering) +
                          "\n    wheelbase: " + Num(p[k_wheelbase]) +
                          "\n    wheel_radius: " + Num(p[k_radius]) + "\n";
  // The controller's tricycle: these values, no steering offset and no steering gain.
  out->model = c.model;
  out->parameters = p;
  out->parameters[k_radius] = AsWritten(p[k_radius]);
  out->parameters[k_wheelbase] = AsWritten(p[k_wheelbase]);
  out->parameters[k_offset] = 0.0;
  if (const std::optional<int> k_gain = ParameterIndex(c.robot(), "steering_gain")) {
    // Wheel angle = k x measured + phi_0 (tricycle_kinematics.h T3). The controller reads the
    // steering joint as the wheel's angle; a SimpleTransmission's joint = actuator / reduction.
    char text[400];
    std::snprintf(text, sizeof text,
                  "tricycle_controller has no steering gain: the steering joint '%s' must report "
                  "%.9g times the measured angle, e.g. <mechanicalReduction>%.9g"
                  "</mechanicalReduction> in its SimpleTransmission (joint = actuator / "
                  "reduction), before the offset above",
                  steering.c_str(), p[*k_gain], 1.0 / p[*k_gain]);
    out->notes.push_back(text);
    out->parameters[*k_gain] = 1.0;
  }
}

struct ControllerEntry {
  const char* name;
  const char* model;    // the fitcal model(s) it takes, for the mismatch message
  const char* distros;  // the distributions that ship it (tests/data/ros2_controllers/)
  // Appends the parameter lines and notes and sets the controller's kinematics.
  void (*write)(const Calibrated&, const std::string& distro, Ros2ControlExport*);
};
const ControllerEntry kControllers[] = {
    {"diff_drive_controller", "diff_drive", "humble jazzy rolling", DiffDriveParameters},
    {"mecanum_drive_controller", "omni", "humble jazzy rolling", MecanumParameters},
    {"omni_wheel_drive_controller", "omni3 omni", "jazzy rolling", OmniWheelParameters},
    {"tricycle_controller", "tricycle", "humble jazzy rolling", TricycleParameters},
};

const ControllerEntry& FindController(const std::string& name) {
  for (const ControllerEntry& e : kControllers) {
    if (name == e.name) return e;
  }
  std::string known;
  for (const ControllerEntry& e : kControllers)
    known += (known.empty() ? "" : ", ") + std::string(e.name);
  throw UsageError("unknown controller '" + name + "' (fitcal writes " + known + ")");
}

bool InList(const char* list, const std::string& word) {
  return (std::string(" ") + list + " ").find(" " + word + " ") != std::string::npos;
}

bool TakesModel(const ControllerEntry& e, const std::string& model) {
  return InList(e.model, model);
}

void CheckDistro(const ControllerEntry& e, const std::string& distro) {
  const std::vector<std::string>& all = RosDistros();
  if (std::find(all.begin(), all.end(), distro) == all.end()) {
    std::string known;
    for (const std::string& d : all) known += (known.empty() ? "" : ", ") + d;
    throw UsageError("--ros-distro '" + distro + "' is not one of " + known);
  }
  if (!InList(e.distros, distro)) {
    throw UsageError(std::string(e.name) + " is not in ROS 2 " + distro + " (it ships in " +
                     e.distros + ")");
  }
}

// The controller's parameters describe the base; a controller model that replaced the calibrated
// one (omni, mecanum) is replayed against the ground truth through the calibrated frame still
// (models/mounted_model.h), or its held-out check would compare the base with the sensor.
void KeepGroundTruthFrame(const Calibrated& c, Ros2ControlExport* out) {
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

const std::vector<std::string>& Ros2Controllers() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const ControllerEntry& e : kControllers) v.push_back(e.name);
    return v;
  }();
  return names;
}

Ros2ControlExport ExportRos2Control(const RobotModelPtr& calibrated,
                                    const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints,
                                    const std::string& ros_distro) {
  const ControllerEntry& entry = FindController(controller);
  CheckDistro(entry, ros_distro);
  const Calibrated c = WithJoints(calibrated, joints);
  if (!TakesModel(entry, c.robot().model)) {
    throw UsageError(calibration_path + ": robot model '" + c.robot().model + "' does not fit " +
                     controller + " (it takes model " + entry.model + ")");
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
  entry.write(c, ros_distro, &out);
  KeepGroundTruthFrame(c, &out);
  return out;
}

Ros2ControlExport ExportRos2Control(const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints,
                                    const std::string& ros_distro) {
  const ControllerEntry& entry = FindController(controller);
  CheckDistro(entry, ros_distro);
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
                                const std::vector<AlignedRun>& runs,
                                const std::vector<RunLog>& logs) {
  std::map<std::string, const GroundTruthTrack*> track_of;
  for (const RunLog& log : logs) track_of[log.id] = &log.ground_truth;
  std::vector<const GroundTruthTrack*> tracks;
  for (const AlignedRun& run : runs) tracks.push_back(track_of.at(run.id));
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
  r.never_worse = ExportNeverWorse(*nominal, exported, runs, logs);
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
  return "[" + Num(planar[0]) + ", " + Num(planar[1]) + ", " + Num(kUnmeasuredVariance) + ", " +
         Num(kUnmeasuredVariance) + ", " + Num(kUnmeasuredVariance) + ", " + Num(planar[2]) + "]";
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
        return "[" + Num(v[0]) + ", " + Num(v[1]) + ", " + Num(v[2]) + "]";
      };
      out += "  odometry_covariance: {interval_s: " + Num(c.interval_s) +
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
    const ControllerEntry& entry = FindController(o.controller);
    CheckDistro(entry, o.ros_distro);
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
