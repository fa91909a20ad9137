#include "io/ros2_parameter_yaml.h"

#include <cstdlib>
#include <set>

#include "io/command_failure.h"
#include "io/text_file.h"
#include "io/yaml_scalar.h"
#include "odometry/text_format.h"

namespace fitcal::io {

std::string Ros2Double(double v) {
  std::string s = StrFormat("%.12g", v);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

double Ros2AsWritten(double v) { return std::strtod(Ros2Double(v).c_str(), nullptr); }

std::string Ros2NameList(const std::vector<std::string>& names) {
  return "[" + Joined(names, ", ", YamlDoubleQuoted) + "]";
}

std::vector<std::string> ChannelJointNames(const Robot& robot,
                                           const std::vector<std::string>& joints) {
  if (joints.empty()) {
    std::vector<std::string> out;
    for (const ChannelInfo& c : robot.channels) out.push_back(c.name);
    return out;
  }
  if (joints.size() != robot.channels.size()) {
    throw UsageError("--joints names " + std::to_string(joints.size()) + " joints; robot '" +
                     robot.name + "' has " + std::to_string(robot.channels.size()) + " channels");
  }
  std::set<std::string> seen;
  for (const std::string& joint : joints) {
    if (!seen.insert(joint).second) {
      throw UsageError("--joints names '" + joint + "' twice; each channel of robot '" +
                       robot.name + "' has a joint of its own");
    }
  }
  return joints;
}

}  // namespace fitcal::io
