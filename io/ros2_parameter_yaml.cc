#include "io/ros2_parameter_yaml.h"

#include <cstdio>
#include <cstdlib>

#include "io/yaml_scalar.h"

namespace fitcal::io {

std::string Ros2Double(double v) {
  char text[40];
  std::snprintf(text, sizeof text, "%.12g", v);
  std::string s = text;
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

double Ros2AsWritten(double v) { return std::strtod(Ros2Double(v).c_str(), nullptr); }

std::string Ros2NameList(const std::vector<std::string>& names) {
  std::string out = "[";
  for (std::size_t i = 0; i < names.size(); ++i) {
    out += (i ? ", " : "") + YamlDoubleQuoted(names[i]);
  }
  return out + "]";
}

}  // namespace fitcal::io
