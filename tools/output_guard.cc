#include "tools/output_guard.h"

#include <cstdio>
#include <exception>

#include "io/yaml_reader.h"

namespace fitcal::tools {

std::string OverwriteRefusal(const std::string& out, const std::string& robot_name) {
  std::FILE* probe = std::fopen(out.c_str(), "rb");
  if (probe == nullptr) return "";
  std::fclose(probe);
  std::string existing;
  try {
    const YAML::Node root = io::LoadYamlFile(out);
    if (root.IsMap() && root["name"] && root["name"].IsScalar()) existing = root["name"].Scalar();
  } catch (const std::exception&) {
    // Not YAML at all: refused below like any file that is not a robot YAML.
  }
  if (existing == robot_name) return "";
  return out + ": " +
         (existing.empty()
              ? std::string("exists and is not a robot YAML")
              : "holds the calibration of robot '" + existing + "', not '" + robot_name + "'") +
         "; refusing to overwrite it (--force to replace it)";
}

}  // namespace fitcal::tools
