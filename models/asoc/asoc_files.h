#pragma once
// Files of ASOC data sets (Doebbler's active split offset castor vehicles; docs/asoc.md, "Data",
// shows both). Encoder CSV, header exactly
//   t,wheel_1a,wheel_1b,wheel_2a,wheel_2b,wheel_3a,wheel_3b,pivot_1,pivot_2,pivot_3
// t in s (strictly increasing); wheel_<i><a|b> the cumulative angle of wheel 1 / 2 of castor i
// (rad); pivot_<i> the pivot encoder reading gamma_i (rad, any turn). At least two rows. The
// robot YAML, `model: asoc`: pivot_distance_m (Doebbler's D: every pair of pivots this far
// apart), three castors, and optional bounds (absolute), odometry (Doebbler Table II's names,
// asoc_kinematics.h), encoder, effects and calibration (informational when read). The generic
// commands read these encoder files through AsocEncoderLogAsChannels (io/dataset.cc).

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <vector>

#include "io/dataset.h"
#include "models/asoc/asoc_model.h"

namespace fitcal::asoc {

// One row of ASOC's encoder CSV: wheel_rad[i][k] the cumulative angle of wheel k (0 = "a" =
// wheel 1, 1 = "b" = wheel 2) of castor i; pivot_rad[i] the pivot encoder reading gamma_i.
struct EncoderSample {
  double wheel_rad[kNumCastors][2] = {{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}};
  double pivot_rad[kNumCastors] = {0.0, 0.0, 0.0};
};

// Samples at strictly increasing times t_s (same length).
struct EncoderLog {
  std::vector<double> t_s;
  std::vector<EncoderSample> samples;
};

}  // namespace fitcal::asoc

namespace fitcal::io {

asoc::EncoderLog ReadAsocEncoderCsv(const std::string& path);
// True when the file's first line is the ASOC encoder header above (read no further).
bool IsAsocEncoderCsv(const std::string& path);
// The log as the asoc model's channels (asoc::kChannelsPerCastor order), one sample per interval:
// each wheel's mean rate (angle increment / dt) and each pivot's angle at the interval's middle
// (cubic midpoint of four readings, along the shorter arc: pivot encoders wrap at +-pi; the mean
// of the two readings at the log's ends; asoc_files.cc).
EncoderLog AsocEncoderLogAsChannels(const asoc::EncoderLog& log);

// `bounds:` of an asoc robot, absolute, one box per kind of parameter (SI, beta in rad).
struct AsocBounds {
  Interval offset_m;
  Interval wheel_radius_m;
  Interval wheel_offset_m;
  Interval encoder_bias_rad;
};

struct AsocRobot {
  std::string name;
  double pivot_distance_m = 0.0;
  std::array<std::string, asoc::kNumCastors> castor_names{"1", "2", "3"};
  asoc::Vehicle nominal;
  std::optional<AsocBounds> bounds;
  std::string odometry = "CAST-0";  // `odometry.algorithm`, checked by the model's reader
  int odometry_line = 0;            // its line in the file, for messages
  bool redundancy_check = false;
  std::optional<EncoderTicks> encoder;
  std::vector<effects::EffectValue> effects;
  // `pivot_resolution_deg` (optional): the pivot encoders' step. The closed form's sigmas
  // propagate it (asoc_geometric.h): two hold runs whose quantised readings agree show no spread.
  // 0: not given.
  double pivot_resolution_rad = 0.0;
};

// From a parsed YAML (`path` names it in messages); the model registry's reader. Throws
// InputError (file, line, cause) on anything malformed or physically impossible.
AsocRobot ReadAsocRobotNode(const YAML::Node& root, const std::string& path);
// The YAML text; `calibration_yaml`, when not empty, is emitted verbatim under `calibration:`
// (a flow map written by the caller). Optional keys are written when set (odometry when not the
// default CAST-0).
std::string AsocRobotYaml(const AsocRobot& robot, const std::string& calibration_yaml = "");

}  // namespace fitcal::io
