#pragma once
// `--clock-offsets` for the commands that replay parameters against a ground truth recorded on
// another clock (`report`, `diagnose`): the ground truth of each clock group (fit/track_residual.h
// ClockGroupOf) is re-stamped by its offset before any run is aligned, so that every figure -
// final poses, drift, ATE, the effects' track fits - reads the ground truth at encoder time t
// from the sample stamped t + dt. One code path for every model.
//
//   recorded  the offsets the calibration YAML records (`clock_offsets:`, written by `fit
//             --clock-offsets ...`), for the runs of the groups it names (report's default)
//   none      the ground truth as stamped
//   session, run, dataset
//             estimated here on these runs' tracks (FitModel's track residuals): with the given
//             parameters held (report), or jointly with the parameters (diagnose)

#include <optional>
#include <string>
#include <vector>

#include "io/calibration_yaml.h"
#include "models/model_interface.h"
#include "odometry/run_log.h"

namespace fitcal {

// Re-stamps logs' ground truth by the offsets `mode` names and returns one line saying what was
// done (printed by the caller). `parameters`: held while estimating (nullptr: estimated jointly
// with the model's parameters from its nominal). `recorded`: the calibration's provenance (for
// "recorded"). Throws std::invalid_argument for an unknown mode.
std::string AlignGroundTruthClocks(const std::string& mode, const RobotModelInterface& model,
                                   const std::vector<double>* parameters,
                                   const std::optional<io::CalibrationProvenance>& recorded,
                                   int threads, std::vector<RunLog>* logs);

}  // namespace fitcal
