#pragma once
// The `calibration:` block every calibrated robot YAML carries, for any model: what produced the
// calibration (method, objective, data set, tool version, termination), which runs trained and
// validated it (repetitions, run ids, trajectories), the CF (Palacin Eq. 14) before and after on
// both, which candidate the result gate chose, the parameters held or resting on a bound, and
// the one-sigma uncertainty of every parameter with their correlation matrix. The model's
// RobotYaml (models/model_interface.h) appends it to its own keys.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "odometry/robot.h"

namespace fitcal::io {

// What produced a calibration and on which runs, with the CF before and after on both: the keys
// every command fills the same way (fit, diagnose).
struct CalibrationSource {
  std::string method;
  std::string objective;
  std::string dataset;
  std::string tool_version;
  std::string termination;
  std::vector<int> training_repetitions;
  std::vector<int> validation_repetitions;
  // Which runs trained it (`fitcal report` validates on every other run of any data set).
  std::vector<std::string> training_run_ids;
  std::string training_trajectories;  // the --train-trajectories selector, when split so
  std::string training_fingerprint;   // of the training runs' encoder logs (training_runs.h)
  int training_runs = 0;
  int validation_runs = 0;
  double cf_training_before = 0.0;
  double cf_training_after = 0.0;
  double cf_validation_before = 0.0;
  double cf_validation_after = 0.0;
  std::vector<std::string> at_bound;  // parameter names resting on a bound
};

// A clock offset the track fit estimated (fit/track_residual.h): the ground truth stamped
// t + offset_s belongs to encoder time t, for the runs of `group` (a session: the runs'
// trajectory label; a run id; or "all").
struct ClockOffsetRecord {
  std::string group;
  double offset_s = 0.0;
  double sigma_s = 0.0;  // 0: no covariance
};

struct CalibrationBlock : CalibrationSource {
  // The result gate (which candidate won, on which runs it was judged).
  std::string selected;
  std::string selected_on;
  std::vector<std::string> held;  // parameter names held at nominal, with why
  // Groups fitted as one value (--tie, fit/parameter_tying.h), "r_left=r_right" each (`tied:`,
  // written only when there are some): a reader of the values sees why they are equal.
  std::vector<std::string> tied;
  // Parameters the runs did not determine: their sigma is what the bounds allow along a direction
  // held at the nominal (`not_determined:`, written only when there are some).
  std::vector<std::string> not_determined;
  bool has_uncertainty = false;
  std::vector<double> sigma;  // one sigma per parameter, SI and rad
  Eigen::MatrixXd correlation;
  // The clock offsets fitted with the parameters (`clock_offsets:`; none when not estimated) and
  // how runs were grouped ("session", "run", "dataset").
  std::string clock_offset_grouping;
  std::vector<ClockOffsetRecord> clock_offsets;
};

// YAML text of the block, starting with "calibration:\n" and indented two spaces; angles' sigmas
// in degrees under keys ending _deg, lengths under keys ending _m.
std::string CalibrationBlockYaml(const CalibrationBlock& record, const Robot& robot);

}  // namespace fitcal::io
