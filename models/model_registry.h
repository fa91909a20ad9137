#pragma once
// Robot models by name: the robot YAML's `model:` picks the reader that builds the robot's
// RobotModelInterface, and what the model offers beyond the seam (model_extras.h: controller
// writers, a simulation scenario, ...) is found here by the commands. The built-in models are
// listed in model_registry.cc (one line each); RegisterModel adds one at run time (a test's own
// model, a plug-in).

#include <yaml-cpp/yaml.h>

#include <functional>
#include <string>
#include <vector>

#include "models/model_extras.h"
#include "models/model_interface.h"

namespace fitcal {

// Builds a robot from the parsed robot YAML (root map; `path` for messages). Throws
// io::InputError naming the file and line for anything malformed or physically impossible, and
// must read every key it accepts so that unknown keys are errors (io/yaml_reader.h).
using RobotModelReader =
    std::function<RobotModelPtr(const YAML::Node& root, const std::string& path)>;

struct ModelRegistration {
  std::string name;     // the YAML's `model:`
  std::string summary;  // one line for `fitcal models` and error messages
  RobotModelReader read;
  // A complete robot YAML of this model: documentation, and the robot every generic test
  // (tests/model_harness_test.cc) runs the model with.
  std::string example_yaml;
  ModelExtras extras;  // from the model's folder, e.g. DiffDriveExtras()
};

// Adds (or replaces) a model; returns true so that it can initialise a static.
bool RegisterModel(ModelRegistration registration);
const std::vector<ModelRegistration>& RegisteredModels();
const ModelRegistration* FindModel(const std::string& name);  // nullptr when unknown
std::string RegisteredModelNames();                           // "omni3, diff_drive, ..."
// The extras of a model by name; none (every field empty) for an unknown name.
const ModelExtras& ExtrasOf(const std::string& name);

// Reads a robot YAML of any registered model; InputError for an unknown `model:`.
RobotModelPtr ReadRobotModelFile(const std::string& path);
// The same from a parsed YAML (`path` names it in messages).
RobotModelPtr ReadRobotModel(const YAML::Node& root, const std::string& path);

}  // namespace fitcal
