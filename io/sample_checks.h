#pragma once
// A model's own check of what its encoder channels hold (a tricycle's steering angle in radians,
// not degrees or ticks), run by the encoder loader (io/log_files.h) on every log of a robot of
// that model, so that no command can forget it. Registered by the model registry
// (models/model_registry.cc) under the robot YAML's `model:` name; throws io::InputError with the
// file and line.

#include <string>

#include "odometry/run_log.h"

namespace fitcal::io {

using SampleCheck = void (*)(const EncoderLog& log, const std::string& path);

void RegisterSampleCheck(const std::string& model, SampleCheck check);

// Runs the check registered for `model`, if any.
void RunSampleCheck(const std::string& model, const EncoderLog& log, const std::string& path);

}  // namespace fitcal::io
