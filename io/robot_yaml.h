#pragma once
// The robot YAML (README.md, "Data set format"): nominal geometry and bounds in, calibrated
// geometry out. The calibrated file has the same schema plus a `calibration:` block, so it can be
// read back as the robot of a new fit.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "io/calibration_block.h"
#include "odometry/robot_description.h"

namespace fitcal::io {

// The `model:` of a robot YAML ("omni3", ...); throws for a file that is not a robot YAML.
std::string ReadRobotModel(const std::string& path);

// The optional `encoder: {ticks_per_rev: N, cumulative: false}` block of any robot YAML (needed
// when the encoder logs are in ticks); nullopt when absent; InputError when malformed.
std::optional<EncoderTicks> ReadEncoderTicks(const std::string& path);

// Reads an omni3 robot; throws InputError on anything malformed or physically impossible
// (non-positive radius, bounds with lo > hi, nominal outside its bounds, ...).
Omni3Robot ReadOmni3Robot(const std::string& path);

// What a calibration did, stored beside the calibrated parameters: the keys every model's
// calibrated YAML has (io/calibration_block.h), then omni3's uncertainty and M^-1 (Eq. 6).
struct CalibrationRecord : CalibrationSource {
  bool has_uncertainty = false;
  std::array<double, omni3::kNumParameters> sigma{};  // one sigma, flat order, SI + rad
  Eigen::Matrix<double, omni3::kNumParameters, omni3::kNumParameters> correlation =
      Eigen::Matrix<double, omni3::kNumParameters, omni3::kNumParameters>::Identity();
  Eigen::Matrix3d inverse_kinematic_matrix = Eigen::Matrix3d::Zero();
};

// The YAML text of a calibrated robot (same schema as the input robot + `calibration:`).
std::string Omni3RobotYaml(const Omni3Robot& robot, const CalibrationRecord* calibration);

}  // namespace fitcal::io
