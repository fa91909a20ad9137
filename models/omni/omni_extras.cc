#include "models/omni/omni_extras.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "io/ros2_parameter_yaml.h"
#include "io/text_file.h"
#include "io/yaml_scalar.h"
#include "models/omni/omni_model.h"
#include "models/omni/omni_trajectories.h"
#include "odometry/pose2.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

constexpr double kDeg = M_PI / 180.0;
// Fixed geometry (drive and roller angles) is written by fitcal with 10 significant digits: a
// difference below this is the same angle.
constexpr double kSameAngleRad = 1e-6;

// The wheels of an omni / omni3 robot at its calibrated values (models/omni/omni_model.h).
std::vector<OmniWheel> OmniGeometry(const CalibratedRobot& c) {
  const std::optional<std::vector<OmniWheel>> wheels = OmniWheelsOf(*c.model, c.robot().nominal);
  if (!wheels) throw std::logic_error("robot '" + c.robot().name + "' has no omni wheels");
  return *wheels;
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

// How far a wheel drives off the x axis, forwards or backwards (rad).
double OffTheXAxis(const OmniWheel& wheel) {
  const double drive = std::abs(WrapAngle(wheel.drive_angle_rad));
  return std::min(drive, M_PI - drive);
}

// A wheel driven straight backwards: the controller's wheel with its rate's sign turned. Its
// roller line is the same (axis at drive + roller angle, a line either way), so the corner's
// roller angle holds for it too (OptiOdom's omni4: the right wheels at 180 deg).
bool DrivesBackwards(const OmniWheel& wheel) {
  return std::abs(WrapAngle(wheel.drive_angle_rad)) > M_PI / 2;
}

// The channel at each corner (kCorners order); std::invalid_argument when the layout differs.
std::vector<int> MecanumCorners(const std::vector<OmniWheel>& wheels, const Robot& robot) {
  std::vector<int> at(4, -1);
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    const double x = wheels[i].distance_m * std::cos(wheels[i].angle_rad);
    const double y = wheels[i].distance_m * std::sin(wheels[i].angle_rad);
    for (int k = 0; k < 4; ++k) {
      if (x * kCorners[k].sign_x > 0 && y * kCorners[k].sign_y > 0) {
        const bool layout =
            OffTheXAxis(wheels[i]) < 15.0 * kDeg &&
            std::abs(wheels[i].roller_angle_rad - kCorners[k].roller_deg * kDeg) < kSameAngleRad;
        if (!layout || at[k] >= 0) {
          throw ControllerCannotDescribe(
              "wheel '" + robot.channels[i].name + "' (" + kCorners[k].key +
              ") is not in mecanum_drive_controller's layout (driven along x, rollers -45 "
              "deg front-left/rear-right, +45 deg front-right/rear-left, one wheel per corner)");
        }
        at[k] = static_cast<int>(i);
      }
    }
  }
  for (int k = 0; k < 4; ++k) {
    if (at[k] < 0) {
      throw ControllerCannotDescribe(std::string("no wheel at the ") + kCorners[k].key +
                                     " corner: not mecanum_drive_controller's layout");
    }
  }
  return at;
}

// Bounds of a robot built from a controller's values: its values lie inside (the replay never
// fits it).
OmniBounds ControllerBounds(double distance_m, double radius_m) {
  return {{0.5 * distance_m, 2 * distance_m},
          {0.5 * radius_m, 2 * radius_m},
          {DegToRad(-2.0), DegToRad(2.0)}};
}

// What mecanum_drive_controller computes: its layout with one radius and lx = ly (any point with
// |x| + |y| = lx + ly gives the controller's yaw row), each wheel driven as the calibrated one
// (backwards: the joint the note asks to invert, replayed as the data record it).
RobotModelPtr MecanumKinematics(const CalibratedRobot& c, const std::vector<OmniWheel>& calibrated,
                                const std::vector<int>& corner, double radius_m, double sum_m) {
  const double distance_m = io::Ros2AsWritten(sum_m) / std::sqrt(2.0);
  std::vector<OmniWheel> wheels(4);
  for (int k = 0; k < 4; ++k) {
    const double drive = DrivesBackwards(calibrated[corner[k]]) ? M_PI : 0.0;
    wheels[corner[k]] = {
        c.ChannelName(corner[k]),    distance_m, std::atan2(kCorners[k].sign_y, kCorners[k].sign_x),
        io::Ros2AsWritten(radius_m), drive,      DegToRad(kCorners[k].roller_deg)};
  }
  return MakeOmniModel(c.robot().name, wheels,
                       ControllerBounds(distance_m, io::Ros2AsWritten(radius_m)));
}

void MecanumParameters(const CalibratedRobot& c, const std::string&, ControllerExport* out) {
  if (c.robot().NumChannels() != 4) {
    throw ControllerCannotDescribe(
        "mecanum_drive_controller takes an omni robot of 4 mecanum wheels");
  }
  const std::vector<OmniWheel> wheels = OmniGeometry(c);
  const std::vector<int> corner = MecanumCorners(wheels, c.robot());
  std::vector<double> radii, sums, drives;
  std::vector<std::string> backwards;
  for (std::size_t i = 0; i < wheels.size(); ++i) {
    const OmniWheel& w = wheels[i];
    radii.push_back(w.radius_m);
    sums.push_back(std::abs(w.distance_m * std::cos(w.angle_rad)) +
                   std::abs(w.distance_m * std::sin(w.angle_rad)));
    drives.push_back(OffTheXAxis(w));
    if (DrivesBackwards(w)) backwards.push_back(c.joints[i]);
  }
  if (!backwards.empty()) {
    out->notes.push_back("mecanum_drive_controller counts a wheel positive when it drives the "
                         "robot forwards, and joints " + io::Joined(backwards, ", ") +
                         " turn the other way: invert their axes in the URDF (or their sign in "
                         "the hardware interface)");
  }
  NoteSpread(radii, "radius", "kinematics.wheels_radius", 1.0, "m", &out->notes);
  NoteSpread(sums, "lx + ly", "kinematics.sum_of_robot_center_projection_on_X_Y_axis", 1.0, "m",
             &out->notes);
  const double worst_drive = *std::max_element(drives.begin(), drives.end());
  if (worst_drive > kSameAngleRad) {
    out->notes.push_back(
        StrFormat("mecanum_drive_controller drives every wheel straight ahead: "
                  "calibrated drive directions up to %.4g deg off it are written as 0",
                  worst_drive / kDeg));
  }
  for (int k = 0; k < 4; ++k) {
    out->parameters_yaml += std::string("    ") + kCorners[k].key + "_wheel_command_joint_name: " +
                            io::YamlDoubleQuoted(c.joints[corner[k]]) + "\n";
  }
  out->parameters_yaml +=
      "    kinematics:\n      wheels_radius: " + io::Ros2Double(MeanValue(radii)) +
      "\n      sum_of_robot_center_projection_on_X_Y_axis: " + io::Ros2Double(MeanValue(sums)) +
      "\n";
  out->model = MecanumKinematics(c, wheels, corner, MeanValue(radii), MeanValue(sums));
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
    if (s == 0 || (sense != 0 && s != sense) ||
        std::abs(wheels[i].roller_angle_rad) > kSameAngleRad) {
      throw ControllerCannotDescribe("wheel '" + robot.channels[i].name +
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
void OmniWheelKinematics(const CalibratedRobot& c, const std::vector<int>& order, double offset_rad,
                         double distance_m, double radius_m, int sense, OmniWheelReplay replay,
                         ControllerExport* out) {
  const int n = static_cast<int>(order.size());
  std::vector<OmniWheel> wheels(n);
  for (int j = 0; j < n; ++j) {
    const double angle = io::Ros2AsWritten(offset_rad) + 2 * M_PI * j / n;
    wheels[order[j]] = {c.ChannelName(order[j]),     io::Ros2AsWritten(distance_m), angle,
                        io::Ros2AsWritten(radius_m), angle + sense * M_PI / 2,      0.0};
  }
  if (replay == OmniWheelReplay::kControllerGeometry) {
    out->model =
        MakeOmniModel(c.robot().name, wheels,
                      ControllerBounds(io::Ros2AsWritten(distance_m), io::Ros2AsWritten(radius_m)));
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

void OmniWheelParameters(const CalibratedRobot& c, OmniWheelReplay replay, ControllerExport* out) {
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
    out->notes.push_back(
        StrFormat("omni_wheel_drive_controller spaces the wheels equally (%.4g "
                  "deg apart): the calibrated wheel angles are up to %.4g deg off that",
                  360.0 / n, worst / kDeg));
  }
  if (sense > 0) {
    out->notes.push_back(
        "omni_wheel_drive_controller counts a wheel positive when it turns the robot clockwise "
        "(w r = sin(a) vx - cos(a) vy - R omega), this robot's wheels counter-clockwise: invert "
        "the wheel joints' axes in the URDF (or their sign in the hardware interface)");
  }
  out->parameters_yaml += "    wheel_names: " + io::Ros2NameList(names) +
                          "\n    wheel_offset: " + io::Ros2Double(offset) +
                          "\n    robot_radius: " + io::Ros2Double(MeanValue(distances)) +
                          "\n    wheel_radius: " + io::Ros2Double(MeanValue(radii)) + "\n";
  OmniWheelKinematics(c, order, offset, MeanValue(distances), MeanValue(radii), sense, replay, out);
}

std::vector<sim::TrajectorySpec> OmniScenario(const RobotModelInterface& /*model*/,
                                              const std::vector<double>& /*truth*/,
                                              int repetitions) {
  sim::OmniTrajectoryOptions shapes;
  shapes.spin_angle_rad = 2.0 * M_PI;
  return sim::OmniFlowerTrajectories(repetitions, shapes);
}

}  // namespace

ControllerWriter OmniWheelController(OmniWheelReplay replay) {
  return {"omni_wheel_drive_controller", "jazzy rolling",
          [replay](const CalibratedRobot& c, const std::string&, ControllerExport* out) {
            OmniWheelParameters(c, replay, out);
          }};
}

ModelExtras OmniExtras() {
  ModelExtras extras;
  extras.controllers = {{"mecanum_drive_controller", "humble jazzy rolling", &MecanumParameters},
                        OmniWheelController(OmniWheelReplay::kControllerGeometry)};
  extras.scenario.trajectories = &OmniScenario;
  return extras;
}

}  // namespace fitcal
