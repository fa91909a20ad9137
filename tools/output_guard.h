#pragma once
// `--out` must not silently replace another robot's calibration. Shared by every command that
// writes a calibrated robot YAML.

#include <string>

namespace fitcal::tools {

// Empty when writing `out` is fine: it does not exist, or it is a robot YAML of the same `name`.
// Otherwise the one-line reason to refuse (the caller allows it with --force).
std::string OverwriteRefusal(const std::string& out, const std::string& robot_name);

}  // namespace fitcal::tools
