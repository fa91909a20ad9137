#pragma once
// Units a robot YAML says in its keys, checked on the values before any model reads them, the same
// for every model: a key ending in `_m` holds metres, one ending in `_deg` degrees (the I/O edge;
// radians inside). Two slips are common and silent otherwise - the fit starts from a robot a
// thousand times too large (reported later as "miswired encoders") or with its wheels a few
// degrees apart (reported as "no calibration beats the nominal"):
//   - a length in millimetres: any `_m` value beyond kMaxRobotLengthM;
//   - angles in radians: the same `_deg` key of three or more list entries (wheels, castors) whose
//     values all lie within one radian-sized turn (|v| <= 2 pi) yet differ by more than a degree:
//     wheel mounting angles in degrees are tens of degrees apart, in radians they are not.
// Each is an io::InputError naming the file, the key's line and the likely unit.

#include <yaml-cpp/yaml.h>

#include <string>

namespace fitcal::io {

inline constexpr double kMaxRobotLengthM = 20.0;

void CheckRobotYamlUnits(const YAML::Node& root, const std::string& path);

}  // namespace fitcal::io
