#include "tools/export_ros2_control.h"

#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include "fit/final_pose_errors.h"
#include "io/atomic_file.h"
#include "io/calibration_yaml.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/yaml_reader.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "odometry/effects.h"
#include "io/text_file.h"
#include "validation/odometry_covariance.h"
#include "validation/training_runs.h"
#include "tools/output_guard.h"

namespace fitcal::tools {
namespace {

using io::InputError;
using io::InputErrorKind;

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

std::string Quoted(const std::string& s) { return "\"" + s + "\""; }

std::string NameList(const std::vector<std::string>& names) {
  std::string out = "[";
  for (std::size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + Quoted(names[i]);
  return out + "]";
}

struct Calibrated {
  RobotModelPtr model;
  YAML::Node root;
  std::vector<std::string> joints;  // robot channel order
  const Robot& robot() const { return model->robot(); }
  const std::vector<double>& p() const { return model->robot().nominal; }
};

Calibrated ReadCalibrated(const std::string& path, const std::vector<std::string>& joints) {
  Calibrated c;
  c.root = io::LoadYamlFile(path);
  c.model = ReadRobotModel(c.root, path);
  const Robot& robot = c.model->robot();
  if (!joints.empty() && joints.size() != robot.channels.size()) {
    throw std::invalid_argument("--joints names " + std::to_string(joints.size()) +
                                " joints; robot '" + robot.name + "' has " +
                                std::to_string(robot.channels.size()) + " channels");
  }
  for (std::size_t j = 0; j < robot.channels.size(); ++j) {
    c.joints.push_back(joints.empty() ? robot.channels[j].name : joints[j]);
  }
  return c;
}

// One wheel of an omni / omni3 robot: position, radius and fixed geometry (omni_kinematics.h).
struct OmniWheelGeometry {
  double distance_m, angle_rad, radius_m, drive_rad, roller_rad;
};

std::vector<OmniWheelGeometry> OmniGeometry(const Calibrated& c) {
  const int n = c.robot().NumChannels();
  std::vector<OmniWheelGeometry> out;
  for (int i = 0; i < n; ++i) {
    OmniWheelGeometry w{c.p()[i], c.p()[2 * n + i], c.p()[n + i], 0.0, 0.0};
    w.drive_rad = w.angle_rad + M_PI / 2.0;  // omni3 and the omni default: tangential, CCW
    const YAML::Node yaml = c.root["wheels"][i];
    if (c.robot().model == "omni" && yaml["drive_angle_deg"]) {
      w.drive_rad = yaml["drive_angle_deg"].as<double>() * kDeg;
    }
    if (c.robot().model == "omni" && yaml["roller_angle_deg"]) {
      w.roller_rad = yaml["roller_angle_deg"].as<double>() * kDeg;
    }
    out.push_back(w);
  }
  return out;
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

std::string DiffDriveParameters(const Calibrated& c, const std::string& distro,
                                std::vector<std::string>*) {
  const int right = DiffDriveRightChannel(*c.model), left = 1 - right;
  const double r_right = c.p()[right], r_left = c.p()[left];
  const double radius = 0.5 * (r_right + r_left);
  return "    left_wheel_names: " + NameList({c.joints[left]}) +
         "\n    right_wheel_names: " + NameList({c.joints[right]}) +
         // humble declares wheels_per_side (and overwrites it with the names' count); jazzy and
         // rolling no longer declare it, and an undeclared key is ignored there.
         (distro == "humble" ? "\n    wheels_per_side: 1" : "") + "\n    wheel_separation: " +
         Num(c.p()[diff_drive::kSeparationIndex]) + "\n    wheel_radius: " + Num(radius) +
         "\n    wheel_separation_multiplier: 1.0" +
         "\n    left_wheel_radius_multiplier: " + Num(r_left / radius) +
         "\n    right_wheel_radius_multiplier: " + Num(r_right / radius) + "\n";
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
std::vector<int> MecanumCorners(const std::vector<OmniWheelGeometry>& wheels, const Robot& robot) {
  std::vector<int> at(4, -1);
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    const double x = wheels[i].distance_m * std::cos(wheels[i].angle_rad);
    const double y = wheels[i].distance_m * std::sin(wheels[i].angle_rad);
    for (int k = 0; k < 4; ++k) {
      if (x * kCorners[k].sign_x > 0 && y * kCorners[k].sign_y > 0) {
        const bool layout =
            std::abs(WrapAngle(wheels[i].drive_rad)) < 15.0 * kDeg &&
            std::abs(wheels[i].roller_rad - kCorners[k].roller_deg * kDeg) < kSameAngleRad;
        if (!layout || at[k] >= 0) {
          throw std::invalid_argument(
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
      throw std::invalid_argument(std::string("no wheel at the ") + kCorners[k].key +
                                  " corner: not mecanum_drive_controller's layout");
    }
  }
  return at;
}

std::string MecanumParameters(const Calibrated& c, const std::string&,
                              std::vector<std::string>* notes) {
  if (c.robot().model != "omni" || c.robot().NumChannels() != 4) {
    throw std::invalid_argument("mecanum_drive_controller takes an omni robot of 4 mecanum wheels");
  }
  const std::vector<OmniWheelGeometry> wheels = OmniGeometry(c);
  const std::vector<int> corner = MecanumCorners(wheels, c.robot());
  std::vector<double> radii, sums, drives;
  for (const OmniWheelGeometry& w : wheels) {
    radii.push_back(w.radius_m);
    sums.push_back(std::abs(w.distance_m * std::cos(w.angle_rad)) +
                   std::abs(w.distance_m * std::sin(w.angle_rad)));
    drives.push_back(std::abs(WrapAngle(w.drive_rad)));
  }
  NoteSpread(radii, "radius", "kinematics.wheels_radius", 1.0, "m", notes);
  NoteSpread(sums, "lx + ly", "kinematics.sum_of_robot_center_projection_on_X_Y_axis", 1.0, "m",
             notes);
  const double worst_drive = *std::max_element(drives.begin(), drives.end());
  if (worst_drive > kSameAngleRad) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "mecanum_drive_controller drives every wheel straight ahead: "
                  "calibrated drive directions up to %.4g deg off it are written as 0",
                  worst_drive / kDeg);
    notes->push_back(text);
  }
  std::string out;
  for (int k = 0; k < 4; ++k) {
    out += std::string("    ") + kCorners[k].key +
           "_wheel_command_joint_name: " + Quoted(c.joints[corner[k]]) + "\n";
  }
  return out + "    kinematics:\n      wheels_radius: " + Num(Mean(radii)) +
         "\n      sum_of_robot_center_projection_on_X_Y_axis: " + Num(Mean(sums)) + "\n";
}

// Which way a positive wheel rate pushes the robot: +1 counter-clockwise (tangential drive, the
// fitcal default), -1 clockwise (omni_wheel_drive_controller's convention).
int OmniDriveSense(const std::vector<OmniWheelGeometry>& wheels, const Robot& robot) {
  int sense = 0;
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    const double offset = WrapAngle(wheels[i].drive_rad - wheels[i].angle_rad);
    const int s = std::abs(offset - M_PI / 2) < kSameAngleRad   ? 1
                  : std::abs(offset + M_PI / 2) < kSameAngleRad ? -1
                                                                : 0;
    if (s == 0 || (sense != 0 && s != sense) || std::abs(wheels[i].roller_rad) > kSameAngleRad) {
      throw std::invalid_argument("wheel '" + robot.channels[i].name +
                                  "' is not an omni wheel driven tangentially like the others: "
                                  "omni_wheel_drive_controller cannot describe it");
    }
    sense = s;
  }
  return sense;
}

// The wheels in omni_wheel_drive_controller's order: anticlockwise from the one nearest the x
// axis; returns the order and the offset (circular mean of angle_j - 2 pi j / n).
std::vector<int> OmniOrder(const std::vector<OmniWheelGeometry>& wheels, double* offset_rad) {
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

std::string OmniWheelParameters(const Calibrated& c, const std::string&,
                               std::vector<std::string>* notes) {
  if (c.robot().model != "omni3" && c.robot().model != "omni") {
    throw std::invalid_argument("omni_wheel_drive_controller takes an omni3 or omni robot");
  }
  const std::vector<OmniWheelGeometry> wheels = OmniGeometry(c);
  const int sense = OmniDriveSense(wheels, c.robot());
  double offset = 0.0;
  const std::vector<int> order = OmniOrder(wheels, &offset);
  const int n = static_cast<int>(wheels.size());
  std::vector<double> radii, distances;
  double worst = 0.0;
  std::vector<std::string> names;
  for (int j = 0; j < n; ++j) {
    const OmniWheelGeometry& w = wheels[order[j]];
    radii.push_back(w.radius_m);
    distances.push_back(w.distance_m);
    worst = std::max(worst, std::abs(WrapAngle(w.angle_rad - offset - 2 * M_PI * j / n)));
    names.push_back(c.joints[order[j]]);
  }
  NoteSpread(radii, "radius", "wheel_radius", 1.0, "m", notes);
  NoteSpread(distances, "distance", "robot_radius", 1.0, "m", notes);
  if (worst > kSameAngleRad) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "omni_wheel_drive_controller spaces the wheels equally (%.4g "
                  "deg apart): the calibrated wheel angles are up to %.4g deg off that",
                  360.0 / n, worst / kDeg);
    notes->push_back(text);
  }
  if (sense > 0) {
    notes->push_back(
        "omni_wheel_drive_controller counts a wheel positive when it turns the robot clockwise "
        "(w r = sin(a) vx - cos(a) vy - R omega), this robot's wheels counter-clockwise: invert "
        "the wheel joints' axes in the URDF (or their sign in the hardware interface)");
  }
  return "    wheel_names: " + NameList(names) + "\n    wheel_offset: " + Num(offset) +
         "\n    robot_radius: " + Num(Mean(distances)) + "\n    wheel_radius: " + Num(Mean(radii)) +
         "\n";
}

std::string TricycleParameters(const Calibrated& c, const std::string&,
                               std::vector<std::string>* notes) {
  const double offset_rad = c.p()[2];
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
                  offset_rad, offset_rad / kDeg, c.joints[1].c_str(), offset_rad / kDeg,
                  offset_rad);
    notes->push_back(text);
  }
  return "    traction_joint_name: " + Quoted(c.joints[0]) +
         "\n    steering_joint_name: " + Quoted(c.joints[1]) + "\n    wheelbase: " + Num(c.p()[1]) +
         "\n    wheel_radius: " + Num(c.p()[0]) + "\n";
}

struct ControllerEntry {
  const char* name;
  const char* model;    // the fitcal model(s) it takes, for the mismatch message
  const char* distros;  // the distributions that ship it (tests/data/ros2_controllers/)
  std::string (*write)(const Calibrated&, const std::string& distro, std::vector<std::string>*);
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
  throw std::invalid_argument("unknown controller '" + name + "' (fitcal writes " + known + ")");
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
    throw std::invalid_argument("--ros-distro '" + distro + "' is not one of " + known);
  }
  if (!InList(e.distros, distro)) {
    throw std::invalid_argument(std::string(e.name) + " is not in ROS 2 " + distro +
                                " (it ships in " + e.distros + ")");
  }
}

// ---------------------------------------------------------------------------------------------
// The reader: controller parameters -> the fitcal robot YAML of the same kinematics.

YAML::Node Require(const YAML::Node& map, const std::string& key, const std::string& what) {
  const YAML::Node node = map[key];
  if (!node) {
    throw InputError(InputErrorKind::kMissingKey, what, map.Mark().line + 1,
                     "ros__parameters has no '" + key + "'");
  }
  return node;
}

double RequireDouble(const YAML::Node& map, const std::string& key, const std::string& what) {
  const YAML::Node node = Require(map, key, what);
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(InputErrorKind::kNonNumeric, what, node.Mark().line + 1,
                     "'" + key + "' is not a number");
  }
}

int ChannelOfJoint(const Calibrated& c, const YAML::Node& node, const std::string& what) {
  const std::string joint =
      node.IsSequence() && node.size() == 1 ? node[0].as<std::string>() : node.as<std::string>();
  for (std::size_t j = 0; j < c.joints.size(); ++j) {
    if (c.joints[j] == joint) return static_cast<int>(j);
  }
  throw InputError(InputErrorKind::kBadValue, what, node.Mark().line + 1,
                   "joint '" + joint + "' is not one of the robot's (--joints)");
}

std::string Bounds(const char* key, double lo, double hi) {
  return std::string(key) + ": [" + Num(lo) + ", " + Num(hi) + "]";
}

std::string DiffDriveRobotText(const Calibrated& c, const YAML::Node& p, const std::string& what) {
  const double radius = RequireDouble(p, "wheel_radius", what);
  const double multiplier = p["wheel_separation_multiplier"]
                                ? RequireDouble(p, "wheel_separation_multiplier", what)
                                : 1.0;
  const double b = RequireDouble(p, "wheel_separation", what) * multiplier;
  double r[2] = {0, 0};
  const char* side[2] = {"", ""};
  for (const char* s : {"left", "right"}) {
    const int ch = ChannelOfJoint(c, Require(p, std::string(s) + "_wheel_names", what), what);
    const std::string key = std::string(s) + "_wheel_radius_multiplier";
    r[ch] = radius * (p[key] ? RequireDouble(p, key, what) : 1.0);
    side[ch] = s;
  }
  std::string text = "model: diff_drive\nname: " + c.robot().name + "\nwheels:\n";
  for (int i = 0; i < 2; ++i) {
    text += "  - {name: " + c.robot().channels[i].name + ", side: " + side[i] +
            ", radius_m: " + Num(r[i]) + "}\n";
  }
  return text + "wheel_separation_m: " + Num(b) + "\nbounds: {" +
         Bounds("radius_m", 0.5 * std::min(r[0], r[1]), 2 * std::max(r[0], r[1])) + ", " +
         Bounds("wheel_separation_m", 0.5 * b, 2 * b) + "}\n";
}

std::string OmniWheelLine(const std::string& name, double distance, double angle_rad, double radius,
                          const std::string& extra) {
  return "  - {name: " + name + ", distance_m: " + Num(distance) +
         ", angle_deg: " + Num(angle_rad / kDeg) + ", radius_m: " + Num(radius) + extra + "}\n";
}

std::string OmniBounds(double distance, double radius) {
  return "bounds: {" + Bounds("distance_m", 0.5 * distance, 2 * distance) + ", " +
         Bounds("radius_m", 0.5 * radius, 2 * radius) + ", angle_offset_deg: [-2.0, 2.0]}\n";
}

std::string MecanumRobotText(const Calibrated& c, const YAML::Node& p, const std::string& what) {
  const YAML::Node k = Require(p, "kinematics", what);
  const double radius = RequireDouble(k, "wheels_radius", what);
  const double sum = RequireDouble(k, "sum_of_robot_center_projection_on_X_Y_axis", what);
  std::vector<std::string> lines(4);
  for (const MecanumCorner& corner : kCorners) {
    const int ch = ChannelOfJoint(
        c, Require(p, std::string(corner.key) + "_wheel_command_joint_name", what), what);
    // Any point with |x| + |y| = lx + ly gives the controller's yaw row; take lx = ly.
    const double angle = std::atan2(corner.sign_y, corner.sign_x);
    lines[ch] =
        OmniWheelLine(c.robot().channels[ch].name, sum / std::sqrt(2.0), angle, radius,
                      ", drive_angle_deg: 0.0, roller_angle_deg: " + Num(corner.roller_deg));
  }
  std::string text = "model: omni\nname: " + c.robot().name + "\nwheels:\n";
  for (const std::string& l : lines) text += l;
  return text + OmniBounds(sum / std::sqrt(2.0), radius);
}

std::string OmniRobotText(const Calibrated& c, const YAML::Node& p, const std::string& what) {
  const double radius = RequireDouble(p, "wheel_radius", what);
  const double distance = RequireDouble(p, "robot_radius", what);
  const double offset = RequireDouble(p, "wheel_offset", what);
  const YAML::Node names = Require(p, "wheel_names", what);
  const int n = c.robot().NumChannels();
  if (!names.IsSequence() || static_cast<int>(names.size()) != n) {
    throw InputError(InputErrorKind::kBadValue, what, names.Mark().line + 1,
                     "wheel_names must list the robot's " + std::to_string(n) + " wheels");
  }
  const int sense = OmniDriveSense(OmniGeometry(c), c.robot());
  std::vector<std::string> lines(n);
  for (int j = 0; j < n; ++j) {
    const int ch = ChannelOfJoint(c, names[j], what);
    const double angle = offset + 2 * M_PI * j / n;
    const std::string extra = c.robot().model == "omni3"
                                  ? ""
                                  : ", drive_angle_deg: " + Num((angle + sense * M_PI / 2) / kDeg) +
                                        ", roller_angle_deg: 0.0";
    lines[ch] = OmniWheelLine(c.robot().channels[ch].name, distance, angle, radius, extra);
  }
  std::string text = "model: " + c.robot().model + "\nname: " + c.robot().name + "\nwheels:\n";
  for (const std::string& l : lines) text += l;
  return text + OmniBounds(distance, radius);
}

std::string TricycleRobotText(const Calibrated& c, const YAML::Node& p, const std::string& what) {
  const double radius = RequireDouble(p, "wheel_radius", what);
  const double wheelbase = RequireDouble(p, "wheelbase", what);
  if (ChannelOfJoint(c, Require(p, "traction_joint_name", what), what) != 0 ||
      ChannelOfJoint(c, Require(p, "steering_joint_name", what), what) != 1) {
    throw InputError(InputErrorKind::kBadValue, what, p.Mark().line + 1,
                     "traction and steering joints are swapped");
  }
  return "model: tricycle\nname: " + c.robot().name +
         "\ntraction_wheel: {name: " + c.robot().channels[0].name + ", radius_m: " + Num(radius) +
         "}\nwheelbase_m: " + Num(wheelbase) + "\nsteering_offset_deg: 0.0\nbounds: {" +
         Bounds("radius_m", 0.5 * radius, 2 * radius) + ", " +
         Bounds("wheelbase_m", 0.5 * wheelbase, 2 * wheelbase) +
         ", steering_offset_deg: [-10.0, 10.0]}\n";
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

Ros2ControlExport ExportRos2Control(const std::string& calibration_path,
                                    const std::string& controller, const std::string& node_name,
                                    const std::vector<std::string>& joints,
                                    const std::string& ros_distro) {
  const ControllerEntry& entry = FindController(controller);
  CheckDistro(entry, ros_distro);
  const Calibrated c = ReadCalibrated(calibration_path, joints);
  if (!TakesModel(entry, c.robot().model)) {
    throw std::invalid_argument(calibration_path + ": robot model '" + c.robot().model +
                                "' does not fit " + controller + " (it takes model " + entry.model +
                                ")");
  }
  if (!c.robot().effects.empty()) {
    // Its parameters were fitted together with the effects, which the controller cannot apply:
    // alone they are worse than a calibration fitted without effects.
    std::string names;
    for (const effects::EffectValue& e : c.robot().effects) {
      names += (names.empty() ? "" : ", ") + std::string(effects::Info(e.id).name);
    }
    throw std::invalid_argument(calibration_path + ": the calibration carries effects (" + names +
                                ") that " + controller +
                                " cannot apply; export a calibration fitted without effects");
  }
  Ros2ControlExport out;
  out.parameters_yaml = (node_name.empty() ? controller : node_name) + ":\n  ros__parameters:\n" +
                        entry.write(c, ros_distro, &out.notes);
  return out;
}

}  // namespace fitcal::tools

namespace fitcal::tools {

RobotModelPtr ReadRos2ControlYaml(const std::string& yaml_text, const std::string& what,
                                  const std::string& calibration_path,
                                  const std::vector<std::string>& joints) {
  const Calibrated c = ReadCalibrated(calibration_path, joints);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw InputError(InputErrorKind::kYamlSyntax, what, e.mark.line + 1, e.msg);
  }
  if (!root.IsMap() || root.size() != 1 || !root.begin()->second.IsMap() ||
      !root.begin()->second["ros__parameters"]) {
    throw InputError(InputErrorKind::kWrongYamlType, what, 1,
                     "expected one '<controller>: ros__parameters:' map");
  }
  const YAML::Node p = root.begin()->second["ros__parameters"];
  std::string robot_text;
  const std::string& model = c.robot().model;
  if (p["wheel_separation"] && model == "diff_drive") {
    robot_text = DiffDriveRobotText(c, p, what);
  } else if (p["kinematics"] && model == "omni") {
    robot_text = MecanumRobotText(c, p, what);
  } else if (p["robot_radius"] && (model == "omni" || model == "omni3")) {
    robot_text = OmniRobotText(c, p, what);
  } else if (p["wheelbase"] && model == "tricycle") {
    robot_text = TricycleRobotText(c, p, what);
  } else {
    throw InputError(InputErrorKind::kBadValue, what, 1,
                     "not the parameters of a controller for robot model '" + model + "'");
  }
  return ReadRobotModel(YAML::Load(robot_text), what + " (as a " + model + " robot)");
}

}  // namespace fitcal::tools

namespace fitcal::tools {

std::vector<AlignedRun> ExportHeldOutRuns(const std::string& calibration_path,
                                          const std::string& logs, const Robot& robot,
                                          std::string* which,
                                          std::vector<RunLog>* held_out_logs) {
  const io::Dataset data = io::LoadDataset(io::ReadDatasetIndex(logs), robot);
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
  std::vector<AlignedRun> runs;
  if (t.split.validation.empty()) {
    *which = "(the calibration trained on every run of this data set)";
    runs = std::move(t.split.training);
  } else {
    *which = t.how == "none" ? "(none of them trained the calibration)"
                             : "held out from the calibration";
    runs = std::move(t.split.validation);
  }
  if (held_out_logs != nullptr) {
    std::set<std::string> ids;
    for (const AlignedRun& r : runs) ids.insert(r.id);
    for (const RunLog& r : data.runs) {
      if (ids.count(r.id) > 0) held_out_logs->push_back(r);
    }
  }
  return runs;
}

namespace {

// The exported parameters replayed on the held-out runs beside the nominal robot and the exact
// calibration: CF (Palacin Eq. 14) of each, and the odometry covariance of both calibrations.
struct Replay {
  std::size_t runs = 0;
  std::string which;
  double cf_nominal = 0.0, cf_exact = 0.0, cf_exported = 0.0;
  OdometryCovariance exported_covariance, exact_covariance;
  bool Worse() const { return cf_exported > cf_nominal; }
};

// Twist errors are taken over windows of this length (docs/ros2.md: long enough that the
// ground truth's own noise is small beside the odometry's drift, short beside a run).
constexpr double kCovarianceWindowS = 1.0;

Replay ReplayOnHeldOutRuns(const ExportRos2ControlOptions& o, const std::string& parameters_yaml) {
  const RobotModelPtr exact = ReadRobotModelFile(o.calibration);
  const RobotModelPtr exported =
      ReadRos2ControlYaml(parameters_yaml, o.controller, o.calibration, o.joints);
  const io::DatasetIndex index = io::ReadDatasetIndex(o.logs);
  const RobotModelPtr nominal = ReadRobotModelFile(index.robot_path);
  if (nominal->robot().model != exact->robot().model) {
    throw std::invalid_argument(o.logs + ": its robot is a " + nominal->robot().model +
                                ", the calibration a " + exact->robot().model);
  }
  Replay r;
  std::vector<RunLog> logs;
  const std::vector<AlignedRun> runs =
      ExportHeldOutRuns(o.calibration, o.logs, exact->robot(), &r.which, &logs);
  r.runs = runs.size();
  r.cf_nominal = EvaluateFinalPoseErrors(*nominal, nominal->robot().nominal, runs).cf;
  r.cf_exact = EvaluateFinalPoseErrors(*exact, exact->robot().nominal, runs).cf;
  r.cf_exported = EvaluateFinalPoseErrors(*exported, exported->robot().nominal, runs).cf;
  for (auto [model, covariance] : {std::make_pair(exported.get(), &r.exported_covariance),
                                   std::make_pair(exact.get(), &r.exact_covariance)}) {
    *covariance = EstimateOdometryCovariance(
        CollectOdometryErrors(*model, model->robot().nominal, logs, kCovarianceWindowS),
        kCovarianceWindowS);
  }
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
    return "    diagonal_covariance:\n      pose: " + Diagonal(c.pose_variance_per_m) +
           "\n      twist: " + Diagonal(c.twist_variance) + "\n";
  }
  return "    pose_covariance_diagonal: " + Diagonal(c.pose_variance_per_m) +
         "\n    twist_covariance_diagonal: " + Diagonal(c.twist_variance) + "\n";
}

namespace {

std::string CovarianceLine(const OdometryCovariance& c) {
  char text[400];
  std::snprintf(text, sizeof text,
                "odometry covariance from %zu held-out runs (%zu windows of %.1f s): twist sigma "
                "vx %.4g m/s, vy %.4g m/s, omega %.4g rad/s; pose sigma per sqrt(m) x %.4g m, "
                "y %.4g m, theta %.4g rad",
                c.runs, c.windows, c.window_s, std::sqrt(c.twist_variance[0]),
                std::sqrt(c.twist_variance[1]), std::sqrt(c.twist_variance[2]),
                std::sqrt(c.pose_variance_per_m[0]), std::sqrt(c.pose_variance_per_m[1]),
                std::sqrt(c.pose_variance_per_m[2]));
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
      out += "  odometry_covariance: {window_s: " + Num(c.window_s) +
             ", held_out_runs: " + std::to_string(c.runs) + ", windows: " +
             std::to_string(c.windows) + ", twist_variance: [" + Num(c.twist_variance[0]) +
             ", " + Num(c.twist_variance[1]) + ", " + Num(c.twist_variance[2]) +
             "], pose_variance_per_m: [" + Num(c.pose_variance_per_m[0]) + ", " +
             Num(c.pose_variance_per_m[1]) + ", " + Num(c.pose_variance_per_m[2]) + "]}\n";
    }
  }
  if (!found) {
    throw std::invalid_argument(path + ": no calibration: block (a calibration written by fit) "
                                "to hold the odometry covariance (--calibration-out)");
  }
  return out;
}

// Thrown when the exported parameters would make the robot worse: exit 5, nothing written.
struct WorseThanNominal : std::runtime_error {
  using std::runtime_error::runtime_error;
};

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
  app.add_option("--calibration-out", o.calibration_out,
                 "With --logs: write the calibration with its odometry covariance here");
  app.add_flag("--force", o.force, "Overwrite --out");
}

int RunExportRos2ControlCommand(const ExportRos2ControlOptions& o) {
  constexpr const char* kPrefix = "fitcal export ros2-control: ";
  try {
    if (!o.out.empty()) {  // never over its calibration or the data set (tools/output_guard.h)
      const std::string refusal = OutputFileRefusal(o.out, {o.calibration, o.logs});
      if (!refusal.empty()) throw std::invalid_argument(refusal);
    }
    if (!o.out.empty() && std::filesystem::exists(o.out) && !o.force) {
      throw std::runtime_error(o.out + ": exists; refusing to overwrite it (--force)");
    }
    const Ros2ControlExport e =
        ExportRos2Control(o.calibration, o.controller, o.node_name, o.joints, o.ros_distro);
    std::string text = "# " + o.controller + " parameters (ros2_controllers, ROS 2 " +
                       o.ros_distro + ") from the fitcal calibration " + o.calibration + "\n";
    for (const std::string& note : e.notes) text += "# not representable: " + note + "\n";
    if (!o.calibration_out.empty() && o.logs.empty()) {
      throw std::invalid_argument("--calibration-out needs --logs (the covariance comes from "
                                  "the held-out runs)");
    }
    if (!o.calibration_out.empty() && std::filesystem::exists(o.calibration_out) && !o.force) {
      throw std::runtime_error(o.calibration_out + ": exists; refusing to overwrite it (--force)");
    }
    std::string parameters = e.parameters_yaml, calibration_text;
    if (!o.logs.empty()) {
      const Replay replay = ReplayOnHeldOutRuns(o, e.parameters_yaml);
      // On stdout beside a written file; in the YAML's comments either way (stdout stays YAML).
      const std::string line = ReplayLine(o, replay);
      if (!o.out.empty()) std::printf("%s\n", line.c_str());
      if (replay.Worse() && !o.allow_worse) {
        char text_worse[300];
        std::snprintf(text_worse, sizeof text_worse,
                      "these parameters replay worse than the nominal robot (CF %.6f > %.6f on "
                      "%zu runs); nothing written (--allow-worse writes them%s)",
                      replay.cf_exported, replay.cf_nominal, replay.runs,
                      e.notes.empty() ? ""
                                      : ", with notes on what the controller leaves out: "
                                        "apply that first, e.g. a steering offset");
        throw WorseThanNominal(text_worse);
      }
      text += "# " + line + "\n";
      const std::string covariance = CovarianceLine(replay.exported_covariance);
      if (!o.out.empty()) std::printf("%s\n", covariance.c_str());
      text += "# " + covariance + " (docs/ros2.md)\n";
      parameters += Ros2CovarianceParameters(o.controller, replay.exported_covariance);
      if (!o.calibration_out.empty()) {
        calibration_text = CalibrationWithCovariance(o.calibration, replay.exact_covariance);
      }
    }
    text += parameters;
    // The notes after the verdict: a refusal is one line.
    for (const std::string& note : e.notes) std::cerr << kPrefix << "note: " << note << "\n";
    if (o.out.empty()) {
      std::cout << text;
    } else {
      io::WriteFileAtomically(o.out, text);
    }
    if (!calibration_text.empty()) io::WriteFileAtomically(o.calibration_out, calibration_text);
    return 0;
  } catch (const WorseThanNominal& e) {
    std::cerr << kPrefix << e.what() << "\n";
    return 5;
  } catch (const std::invalid_argument& e) {
    std::cerr << kPrefix << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << kPrefix << e.what() << "\n";
    return 1;
  }
}

}  // namespace fitcal::tools
