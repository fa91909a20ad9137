#pragma once
// Reads back what `fitcal fit` recorded in the `calibration:` block of a calibrated robot YAML
// (io/robot_yaml.h writes it). Only what the report needs: which repetitions trained the fit.

#include <optional>
#include <string>
#include <vector>

namespace fitcal::io {

// The recorded training repetitions, or nullopt when the file has no calibration block (a plain
// robot YAML). Throws InputError (file, line) when the block is present but malformed.
std::optional<std::vector<int>> ReadCalibrationTrainingRepetitions(const std::string& path);

}  // namespace fitcal::io
