#pragma once
// OptiOdom's tricycle recordings (Sousa et al., "OptiOdom: a Generic Approach for Odometry
// Calibration of Wheeled Mobile Robots", J. Intell. Robot. Syst. 105, 39, 2022; MIT licence;
// ../shared/data/optiodom/tricyc/{circular,square}/<session>/) as a fitcal data set of a
// `tricycle` robot (models/tricycle/).
//
// Published format, per session directory <s>/:
//   <s>_metadata.csv  rows `key,v1,...`: type (tricyc), ngear, encRes (counts per motor
//                     revolution), Li (wheelbase L, m), Di (traction wheel diameter, m), Thi
//                     (steering offset, rad: the authors' simulateRobot_tricyc.m adds it to the
//                     steering angle in rad), N (runs), L (square side, empty), imarkers,
//                     gt_ti/gt_tf/odo_ti/odo_tf (clock-mapping instants per run)
//   <s>_run-NN.csv    no header, `t_s, x_gt_m, y_gt_m, theta_gt_rad, ticks, steering_rad`:
//                     ground truth of the rear axle's centre in the start frame (heading
//                     unwrapped), traction ticks counted over the 50 ms cycle ending at t, and the
//                     steering angle read at t (radians, not ticks, despite the upstream README).
//
// Conventions, checked against the ground truth (tests/tricycle_test.cc, and the importer's
// channel-order check, tools/import_channel_order.h):
//   - steering sign: positive = counter-clockwise turn, as ours; replaying with the column negated
//     explains the ground truth far worse (fitted SSR 19.2 vs 0.30 over the 28 runs);
//   - traction ticks positive = forward;
//   - steering reading at the cycle's end: the authors' replay uses row k's angle for the cycle
//     ending at row k; the mean of the readings at both ends (the loader's midpoint rule) fits
//     as well (fitted SSR 0.3025 vs 0.3016, well inside the noise): the steering moves almost only
//     while the traction wheel stands still.
// Each session holds two runs: run-01 turns clockwise, run-02 counter-clockwise. The data set
// labels runs by path and direction (trajectory `circular_cw`, `square_ccw`, ...) with the
// session's place among the sessions of that path as the repetition (1 = earliest), so that
// "train on circles", "on squares" and "leave one session out" are label and repetition choices.
//
// Output (README "Data set format"): dataset.yaml, robot.yaml (model tricycle, the metadata's
// nominal values, encoder ticks_per_rev = ngear encRes), runs/<id>_encoders.csv with header
// `t,ticks_traction,steering` (ticks per interval, row 0 zero; steering reading at t) and
// runs/<id>_ground_truth.csv (`t,x,y,theta`).

#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/run_log.h"
#include "tools/optiodom_format.h"

namespace fitcal::tools {

struct OptiOdomTricycleMetadata {
  double gear_ratio = 0.0;              // ngear
  double encoder_counts_per_rev = 0.0;  // encRes
  double wheelbase_m = 0.0;             // Li
  double diameter_m = 0.0;              // Di
  double steering_offset_rad = 0.0;     // Thi
  int num_runs = 0;                     // N
  double TicksPerWheelRev() const { return gear_ratio * encoder_counts_per_rev; }
};

// encoder[k] = {traction ticks over (t(k-1), t(k)], steering reading at t(k) in rad}.
using OptiOdomTricycleRun = optiodom::RunRows;

using OptiOdomTricycleSession = optiodom::Session<OptiOdomTricycleMetadata, OptiOdomTricycleRun>;

// Reads and checks one session directory (metadata, every run, the steering column:
// models/tricycle/tricycle_checks.h); throws io::InputError (file, line, cause).
OptiOdomTricycleSession ReadOptiOdomTricycleSession(const std::string& directory);

// The nominal robot of a session's metadata: r = Di / 2, L = Li, offset = Thi; bounds r +-10 %,
// L +-15 %, offset +-10 deg around them (wide enough for the real robot's -1 deg offset and 3 %
// smaller wheel, narrow enough to keep the wheel from vanishing).
RobotModelPtr OptiOdomTricycleNominalModel(const OptiOdomTricycleMetadata& metadata);

// One run as the replay sees it: traction rate from the ticks, steering per interval the mean
// of the readings at its ends (the loader's midpoint rule), ground truth on the same clock.
// id: <path>_<session>_runNN; trajectory and repetition as described above.
RunLog OptiOdomTricycleRunLog(const OptiOdomTricycleSession& session,
                              const OptiOdomTricycleRun& run, int session_repetition);

struct ImportOptiOdomTricycleOptions {
  bool force = false;            // overwrite a data set already in `out`
  bool skip_sign_check = false;  // write even if other channel signs explain the data better
};

struct ImportOptiOdomTricycleSummary {
  int num_sessions = 0;
  std::vector<RunLog> runs;   // as written, in dataset.yaml order
  std::string channel_order;  // the channel-order check's line (tools/import_channel_order.h)
  std::vector<double> nominal_final_error;  // per run: |(dx, dy, wrap dtheta)| (Palacin Eq. 14)
  double nominal_cf = 0.0;                  // their mean
};

// Reads every session, checks them (one robot, steering in rad within [-pi, pi], the channel
// order and signs: tools/import_channel_order.h), and only then writes the data set to `out`.
// Throws io::InputError for bad input, std::runtime_error when `out` already holds a data set
// (without force) and MiswiredError when the channel check fails; nothing is written then.
ImportOptiOdomTricycleSummary ImportOptiOdomTricycle(
    const std::vector<std::string>& sessions, const std::string& out,
    const ImportOptiOdomTricycleOptions& options = {});

}  // namespace fitcal::tools
