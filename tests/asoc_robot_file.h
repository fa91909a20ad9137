#pragma once
// An ASOC robot YAML read from its file, as the tests check what the commands wrote. The product
// reads robot files through the model registry (models/model_registry.h, ReadRobotModelFile),
// whose asoc reader takes the parsed YAML (io::ReadAsocRobotNode); only the tests want the
// AsocRobot fields of a file by path.

#include <string>

#include "io/yaml_reader.h"
#include "models/asoc/asoc_files.h"

namespace fitcal::io {

// Throws InputError (file, line, cause) on anything malformed or physically impossible.
inline AsocRobot ReadAsocRobot(const std::string& path) {
  return ReadAsocRobotNode(LoadYamlFile(path), path);
}

}  // namespace fitcal::io
