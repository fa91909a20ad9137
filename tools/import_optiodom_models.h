#pragma once
// OptiOdom recordings of robots other than omni3 (Sousa et al., "OptiOdom: a Generic Approach for
// Odometry Calibration of Wheeled Mobile Robots", J. Intell. Robot. Syst. 105, 39, 2022; MIT
// licence; ../shared/data/optiodom/README.md) -> fitcal data sets for the models on the seam.
//
// Differential drive (`diff/{circular,square}/<session>/`):
//   <s>_metadata.csv  rows `key,v1,...`: type diff, ngear (43.7), encRes (64), Li = wheel
//                     separation b (m), Di = wheel diameters right, left (m), N runs, L (square
//                     side, squares only), imarkers, gt_ti/gt_tf/odo_ti/odo_tf (clock mapping
//                     already applied to the run files)
//   <s>_run-NN.csv    no header, `t_s, x_gt_m, y_gt_m, theta_gt_rad, ticks_right, ticks_left`,
//                     ticks = increments over the 50 ms cycle ending at t, positive forward; the
//                     ground truth in the start frame (first row 0, 0, 0; heading unwrapped)
// The importer checks the wheel order and signs on the data (tools/import_channel_order.h, the one
// channel-order check): when a candidate miswiring of the model (right/left swapped, signs flipped)
// explains the ground truth far better than the documented order, nothing is written.
//
// What it writes (README.md "Data set format"): robot.yaml (model diff_drive, wheels right then
// left, the nominal values most sessions declare - some sessions declare perturbed values on
// purpose and are reported, the robot is the same - bounds +-10 % around them, encoder
// {ticks_per_rev: ngear * encRes, cumulative: false}), dataset.yaml, and per run
// runs/<id>_encoders.csv (`t,ticks_right,ticks_left`) and runs/<id>_ground_truth.csv
// (`t,x,y,theta`). Trajectory label `<path type>/<session>` (e.g. `square/231220200029`),
// repetition = run number, id `<path type>-<session>-runNN`.
//
// Flagged runs: diff/square/231220200029 run-02, which the authors flagged as bad, is left out
// unless include_flagged; the importer prints a line for it, and dataset.yaml lists it in a
// comment at its top (a YAML comment: the loader ignores it, a reader sees it).

#include <string>
#include <vector>

#include "odometry/run_log.h"

namespace fitcal::tools {

struct ImportOptiOdomDiffOptions {
  bool include_flagged = false;     // import runs the authors flagged as bad
  bool skip_mapping_check = false;  // write even if another wheel order/sign fits better
  bool force = false;               // overwrite an existing data set
  bool quiet = false;               // print nothing (the summary still says everything)
};

struct OptiOdomDiffImportSummary {
  int num_sessions = 0;
  int num_runs = 0;           // written
  double separation_m = 0.0;  // the robot YAML's nominal values
  double diameter_right_m = 0.0;
  double diameter_left_m = 0.0;
  double ticks_per_rev = 0.0;
  std::vector<std::string> notes;  // sessions with other declared values, runs left out
  double nominal_cf = 0.0;         // Palacin Eq. 14 over the written runs, nominal parameters
  double nominal_mean_position_error_m = 0.0;
  double nominal_mean_heading_error_rad = 0.0;
  std::vector<RunLog> runs;  // as written (wheel rates from the ticks)
};

// Reads every session directory, checks them, and writes the data set to out_dir (created).
// Throws io::InputError for bad input (file, line, cause) and std::runtime_error when the wheel
// mapping check fails or out_dir already holds a data set (without force); nothing is written
// then.
OptiOdomDiffImportSummary ImportOptiOdomDiff(const std::vector<std::string>& session_dirs,
                                             const std::string& out_dir,
                                             const ImportOptiOdomDiffOptions& options = {});

}  // namespace fitcal::tools
