#include "models/model_registry.h"

#include "io/input_error.h"
#include "io/sample_checks.h"
#include "io/text_file.h"
#include "io/yaml_reader.h"
#include "io/yaml_units_check.h"
#include "models/asoc/asoc_extras.h"
#include "models/asoc/asoc_robot_model.h"
#include "models/diff_drive/diff_drive_extras.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/mounted_model.h"
#include "models/omni/omni_extras.h"
#include "models/omni/omni_model.h"
#include "models/omni3/omni3_extras.h"
#include "models/omni3/omni3_robot_model.h"
#include "models/tricycle/tricycle_checks.h"
#include "models/tricycle/tricycle_extras.h"
#include "models/tricycle/tricycle_model.h"

namespace fitcal {

namespace {

// The built-in models, one entry each.
std::vector<ModelRegistration>& Registry() {
  static std::vector<ModelRegistration> registry = {
      {"omni3", "three-wheeled omni robot, Palacin et al. 2022 (9 parameters)", &ReadOmni3Model,
       kOmni3ExampleYaml, Omni3Extras()},
      {"omni", "3 to 8 omni or mecanum wheels (3 parameters per wheel)", &ReadOmniModel,
       kOmniExampleYaml, OmniExtras()},
      {"tricycle", "steered, driven wheel and a rear axle (3 parameters)", &ReadTricycleModel,
       kTricycleExampleYaml, TricycleExtras()},
      {"diff_drive", "differential drive, Borenstein & Feng 1996 (3 parameters)",
       &ReadDiffDriveModel, kDiffDriveExampleYaml, DiffDriveExtras()},
      {"asoc", "three active split offset castors, Doebbler et al. (18 parameters)", &ReadAsocModel,
       kAsocExampleYaml, AsocExtras()},
  };
  // What each model's channels must hold, checked by the loader on every log (io/sample_checks.h).
  static const bool sample_checks_registered = [] {
    io::RegisterSampleCheck("tricycle", &tricycle::CheckSteeringSamples);
    return true;
  }();
  (void)sample_checks_registered;
  return registry;
}

}  // namespace

bool RegisterModel(ModelRegistration registration) {
  auto& registry = Registry();
  for (ModelRegistration& existing : registry) {
    if (existing.name == registration.name) {
      existing = std::move(registration);
      return true;
    }
  }
  registry.push_back(std::move(registration));
  return true;
}

const std::vector<ModelRegistration>& RegisteredModels() { return Registry(); }

const ModelRegistration* FindModel(const std::string& name) {
  for (const ModelRegistration& m : Registry()) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

std::string RegisteredModelNames() {
  return io::Joined(Registry(), ", ", [](const ModelRegistration& m) { return m.name; });
}

const ModelExtras& ExtrasOf(const std::string& name) {
  static const ModelExtras kNone;
  const ModelRegistration* m = FindModel(name);
  return m == nullptr ? kNone : m->extras;
}

RobotModelPtr ReadRobotModelFile(const std::string& path) {
  return ReadRobotModel(io::LoadYamlFile(path), path);
}

namespace {

// A declared effect these channels cannot carry (a steering scale on a differential drive) would
// be replayed as nothing: one line instead, at the effect's entry.
void RefuseEffectsTheChannelsCannotShow(const Robot& robot, const YAML::Node& root,
                                        const std::string& path) {
  const YAML::Node list = root["effects"];
  for (std::size_t i = 0; i < robot.effects.size(); ++i) {
    const effects::EffectId id = robot.effects[i].id;
    if (robot.CanShow(id)) continue;
    const int line = list && list.IsSequence() && i < list.size() ? list[i].Mark().line + 1
                     : list                                       ? list.Mark().line + 1
                                                                  : 1;
    const bool vowel = std::string("aeiou").find(robot.model.substr(0, 1)) != std::string::npos;
    throw io::InputError(
        io::InputErrorKind::kBadValue, path, line,
        std::string("effect ") + effects::Info(id).name + " needs " +
            (effects::NeedsWheelPair(id) ? "exactly two wheel channels and no other"
                                         : "an angle channel (a steering angle)") +
            (vowel ? "; an " : "; a ") + robot.model + " robot cannot carry it");
  }
}

}  // namespace

RobotModelPtr ReadRobotModel(const YAML::Node& root, const std::string& path) {
  io::ExpectYamlType(root, YAML::NodeType::Map, path, "robot file");
  if (!root["model"]) {
    // A misspelt key is named on its own line (YamlMap::Required), else the missing one.
    io::YamlMap robot(root, path, "robot");
    robot.Required("model");
  }
  const std::string model = io::YamlString(root["model"], path, "robot.model");
  const ModelRegistration* registration = FindModel(model);
  if (registration == nullptr) {
    throw io::InputError(io::InputErrorKind::kUnknownModel, path, root["model"].Mark().line + 1,
                         "unknown model '" + model + "' (known: " + RegisteredModelNames() + ")");
  }
  io::CheckRobotYamlUnits(root, path);  // millimetres, radians: before any model reads a value
  // A pose source on a mount wraps any model (models/mounted_model.h).
  RobotModelPtr robot_model = ApplyGroundTruthFrame(
      root, path, [&](const YAML::Node& schema) { return registration->read(schema, path); });
  RefuseEffectsTheChannelsCannotShow(robot_model->robot(), root, path);
  return robot_model;
}

}  // namespace fitcal
