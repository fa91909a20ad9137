#pragma once
// Units a robot YAML says in its keys, checked on the values before any model reads them, the same
// for every model: a key ending in `_m` holds metres, one ending in `_deg` degrees (the I/O edge;
// radians inside). Two slips are common and silent otherwise - the fit starts from a robot a
// thousand times too large (reported later as "miswired encoders") or with its wheels a few
// degrees apart (reported as "no calibration beats the nominal"):
//   - a length in millimetres: any `_m` value beyond kMaxRobotLengthM;
//   - angles in radians: the same mounting-angle key ("angle_deg", "pivot_angle_deg"; not an
//     offset, bias, drive, roller or steering angle) of three or more list entries whose
//     values all lie within one radian-sized turn (|v| <= 2 pi) yet spread over more than pi:
//     wheels mounted around a robot, in radians (60, 180, 300 deg written 1.05, 3.14, 5.24);
//     small offsets in degrees (a calibrated drive angle of -0.6 deg) spread less.
// Each is an io::InputError naming the file, the key's line and the likely unit.

#include <yaml-cpp/yaml.h>

#include <string>

namespace fitcal::io {

inline constexpr double kMaxRobotLengthM = 20.0;

void CheckRobotYamlUnits(const YAML::Node& root, const std::string& path);

}  // namespace fitcal::io
