#pragma once
// A holonomic robot on 3 to 8 omni or mecanum wheels on the model seam: the kinematics of
// omni_kinematics.h, the robot YAML schema below, and the gauge the fit holds.
//
// Robot YAML (`model: omni`), kOmniExampleYaml below: 3..8 wheels in the encoder CSV's column
// order, each with distance_m, angle_deg, radius_m, an optional drive_angle_deg (drive direction
// in the robot frame; default angle_deg + 90, tangential counter-clockwise) and roller_angle_deg
// (default 0, an omni wheel; +-45 mecanum); bounds; optional `encoder:` and `effects:`
// (io/robot_yaml_blocks.h).
// Distance and radius bounds are absolute for every wheel, angle bounds relative to each wheel's
// nominal angle (Palacin Eq. 16). Channels are "w_<name>" (rad/s) or "ticks_<name>".
//
// Gauge. Real wheels agree up to slip, so the recorded rates lie in the range of the true J and
// a replay sees the parameters only through F(p) J_true, a 3 x 3 matrix: at most 9 of the 3 N
// parameters are determinable, whatever the trajectories (for N = 4 in the symmetric layout only
// sums of opposite wheels' distances enter the yaw, cf. ros2_controllers' mecanum
// `sum_of_robot_center_projection_on_X_Y_axis`). The reader finds the directions the odometry
// cannot see at the nominal (SVD of the Jacobian of F(p) J(p_nominal) with respect to p) and holds
// as many parameters as there are such directions: angles, then distances, then radii, each from
// the last wheel backwards and only if it pins a further direction (the scale stays free).
// Robot::held names them and, in parameter terms, what they trade against. The directions are
// invisible to first order; the pseudo-inverse of J + n a^T differs from J's at O(|a|^2).

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

#include "models/model_interface.h"

namespace fitcal {

namespace io {
class YamlMap;  // io/yaml_reader.h
}  // namespace io

inline constexpr int kOmniMinWheels = 3;
inline constexpr int kOmniMaxWheels = 8;

// One wheel as the YAML states it (angles in rad inside the code).
struct OmniWheel {
  std::string name;
  double distance_m = 0.0;
  double angle_rad = 0.0;
  double radius_m = 0.0;
  double drive_angle_rad = 0.0;  // absolute, robot frame; TangentialDriveAngle(angle_rad) default
  double roller_angle_rad = 0.0;
};

inline double TangentialDriveAngle(double angle_rad) { return angle_rad + M_PI / 2.0; }

struct OmniBounds {
  Interval distance_m;
  Interval radius_m;
  Interval angle_offset_rad;  // relative to each wheel's nominal angle
};

// The `bounds:` block of an omni or omni3 robot YAML (the box of Palacin Eq. 16), read strictly;
// InputError for a bound on distance or radius that is not positive.
OmniBounds ReadOmniBounds(io::YamlMap& robot_map, const std::string& path);

// A mecanum robot in ros2_controllers' layout: wheels at (+-0.2, +-0.15) m, all driven forward,
// rollers -45 deg on the front-left/rear-right and +45 deg on the front-right/rear-left wheels.
inline constexpr const char* kOmniExampleYaml = R"(model: omni
name: example_mecanum
wheels:
  - {name: fl, distance_m: 0.25, angle_deg: 36.86989765, radius_m: 0.05, drive_angle_deg: 0,
     roller_angle_deg: -45}
  - {name: fr, distance_m: 0.25, angle_deg: -36.86989765, radius_m: 0.05, drive_angle_deg: 0,
     roller_angle_deg: 45}
  - {name: rl, distance_m: 0.25, angle_deg: 143.13010235, radius_m: 0.05, drive_angle_deg: 0,
     roller_angle_deg: 45}
  - {name: rr, distance_m: 0.25, angle_deg: -143.13010235, radius_m: 0.05, drive_angle_deg: 0,
     roller_angle_deg: -45}
bounds:
  distance_m: [0.22, 0.28]
  radius_m: [0.045, 0.055]
  angle_offset_deg: [-2.0, 2.0]
)";

// The model of these wheels. Throws std::invalid_argument with one line for a wheel count
// outside [3, 8], a repeated name, a non-positive distance or radius, a roller angle not inside
// (-90, 90) deg, a nominal outside the bounds, or a geometry whose kinematic matrix is not of
// full rank (naming the wheels and the motion they cannot sense).
RobotModelPtr MakeOmniModel(const std::string& name, const std::vector<OmniWheel>& wheels,
                            const OmniBounds& bounds,
                            const std::optional<EncoderTicks>& encoder = std::nullopt,
                            const std::vector<effects::EffectValue>& effect_values = {});

// The wheels of an omni-wheeled robot at parameters p: distance, angle and radius found in p by
// the parameter table (R_<wheel>, delta_<wheel>, r_<wheel>), drive and roller directions from an
// `omni` model's fixed geometry, or tangential omni wheels (Palacin's, counter-clockwise) for any
// other model with these parameters (omni3). nullopt for a model without them.
std::optional<std::vector<OmniWheel>> OmniWheelsOf(const RobotModelInterface& model,
                                                   const std::vector<double>& p);

// The reader registered as `omni` (models/model_registry.cc); io::InputError with file and line.
RobotModelPtr ReadOmniModel(const YAML::Node& root, const std::string& path);

}  // namespace fitcal
