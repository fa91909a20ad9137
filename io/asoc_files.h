#pragma once
// Files of ASOC data sets (Doebbler's active split offset castor vehicles):
//
// Encoder CSV, header exactly
//   t,wheel_1a,wheel_1b,wheel_2a,wheel_2b,wheel_3a,wheel_3b,pivot_1,pivot_2,pivot_3
// t in s (strictly increasing); wheel_<i><a|b> the cumulative angle of wheel 1 / 2 of castor i
// (rad); pivot_<i> the pivot encoder reading gamma_i (rad, any turn). At least two rows.
//
// Robot YAML, `model: asoc`:
//   model: asoc
//   name: proto
//   pivot_distance_m: 0.5196      # Doebbler's D: every pair of pivots is this far apart
//   castors:
//     - {name: c1, pivot_radius_m: 0.3, pivot_angle_deg: 0, offset_m: 0.08,
//        wheel_radius_m: [0.04, 0.04], wheel_offset_m: [0.06, 0.06], encoder_bias_deg: 0}
//     - ... (three castors)
//   calibration: {...}            # optional, written by fitcal, informational when read
// Ground truth and dataset.yaml are as for omni3 (io/dataset.h, io/log_files.h).

#include <string>
#include <vector>

#include "io/dataset.h"
#include "models/asoc/asoc_model.h"
#include "models/asoc/asoc_run_log.h"

namespace fitcal::io {

asoc::EncoderLog ReadAsocEncoderCsv(const std::string& path);
std::string AsocEncoderCsv(const asoc::EncoderLog& log);

struct AsocRobot {
  std::string name;
  double pivot_distance_m = 0.0;
  std::array<std::string, asoc::kNumCastors> castor_names{"1", "2", "3"};
  asoc::Vehicle nominal;
};

// Throws InputError (file, line, cause) on anything malformed or physically impossible.
AsocRobot ReadAsocRobot(const std::string& path);
// The YAML text; `calibration_yaml`, when not empty, is emitted verbatim under `calibration:`
// (a flow map written by the caller).
std::string AsocRobotYaml(const AsocRobot& robot, const std::string& calibration_yaml = "");

struct AsocDataset {
  std::string directory;
  std::string robot_path;
  std::vector<asoc::RunLog> runs;
};

// dataset.yaml via ReadDatasetIndex, ASOC encoder CSVs, ground truth as for omni3.
AsocDataset LoadAsocDataset(const std::string& directory, const DatasetOptions& options = {});

}  // namespace fitcal::io
