#pragma once
// Reads back what `fitcal fit` and `fitcal diagnose` recorded in the `calibration:` block of a
// calibrated robot YAML (each model writes it with io/calibration_block.h): what the report needs
// to know which runs trained the calibration and how the solver ended.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "odometry/robot.h"

namespace YAML {
class Node;
}  // namespace YAML

namespace fitcal::io {

// What trained a calibration and how it ended. Keys a file written by an older fitcal lacks stay
// empty (training_run_ids, training_trajectories, training_fingerprint, at_bound).
struct CalibrationProvenance {
  std::string method;
  std::string dataset;      // the --logs the fit was given, as typed
  std::string termination;  // solver termination ("CONVERGENCE", "NO_CONVERGENCE", ...)
  std::vector<int> training_repetitions;
  std::vector<std::string> training_run_ids;
  std::string training_trajectories;  // the --train-trajectories selector; empty by repetition
  std::string training_fingerprint;   // validation/training_runs.h, TrainingFingerprint
  std::vector<std::string> at_bound;  // parameter names resting on a bound
  bool has_training_cf = false;
  double cf_training_before = 0.0, cf_training_after = 0.0;
  // The fit's one-sigma uncertainty as written: keyed "<parameter>_<display unit>" in display
  // units (degrees for angles), with the correlation matrix in the same order; empty when the
  // file records `sigma: ~`.
  std::vector<std::pair<std::string, double>> sigma;
  std::vector<int> sigma_lines;  // the line of each sigma's key, for RecordedSigmas's refusal
  std::string path;              // the file it was read from
  std::vector<std::vector<double>> correlation;
  // `clock_offsets:` (io/calibration_block.h): how runs were grouped, and each group's offset
  // (seconds; the ground truth stamped t + offset belongs to encoder time t) and sigma.
  std::string clock_offset_grouping;
  struct ClockOffset {
    std::string group;
    double offset_s = 0.0;
    double sigma_s = 0.0;
  };
  std::vector<ClockOffset> clock_offsets;
};

// nullopt for a plain robot YAML; InputError (file, line) for a malformed block.
std::optional<CalibrationProvenance> ReadCalibrationProvenance(const std::string& path);
// The same from the file's parsed `root` (a reader that has it need not parse it again).
std::optional<CalibrationProvenance> ReadCalibrationProvenance(const YAML::Node& root,
                                                               const std::string& path);

// The recorded sigmas matched to `parameters` by their written key, in SI units and rad: a
// recorded key names its parameter and display unit, "<name>_<unit>", or for the omni3 file,
// which writes one list per quantity in the parameters' order, "<quantity>_<unit>[i]". Empty
// unless every parameter has one (a file from before a parameter was added to its model). A
// recorded key that names none of `parameters` (an edited `r_rigth_m`) is an InputError at its
// line: its uncertainty would otherwise vanish from every page unsaid.
std::vector<double> RecordedSigmas(const CalibrationProvenance& provenance,
                                   const std::vector<ParameterInfo>& parameters);

}  // namespace fitcal::io
