#pragma once
// What any robot YAML says before a model reads it (README.md, "Data set format"): its `model:`
// and its encoder ticks. Each model reads and writes the rest of its schema itself
// (models/<model>/, through models/model_registry.h).

#include <optional>
#include <string>

#include "odometry/robot.h"

namespace fitcal::io {

// The `model:` of a robot YAML (a registered model's name); throws for a file that is not a
// robot YAML.
std::string ReadRobotModel(const std::string& path);

// The optional `encoder: {ticks_per_rev: N, cumulative: false}` block of any robot YAML (needed
// when the encoder logs are in ticks); nullopt when absent; InputError when malformed.
std::optional<EncoderTicks> ReadEncoderTicks(const std::string& path);

}  // namespace fitcal::io
