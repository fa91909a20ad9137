#pragma once
// Imports the OptiOdom four-wheel recordings (Sousa et al., "OptiOdom: a Generic Approach for
// Odometry Calibration of Wheeled Mobile Robots", J. Intell. Robot. Syst. 105, 39, 2022; MIT
// licence; ../shared/data/optiodom/omni4/{circular,square}/<session>/) as a data set of the
// `omni` model (models/omni/omni_model.h).
//
// Published format, per session directory <s>/:
//   <s>_metadata.csv  rows `key,v1,v2,...`: type (omni4), ngear, encRes, Li (L1, L2 in m),
//                     Di (four diameters, m), N (runs), clock-mapping instants (not needed: the
//                     run files are already synchronised)
//   <s>_run-NN.csv    no header, `t_s, x_gt_m, y_gt_m, theta_gt_rad, enc_1..enc_4`, one row per
//                     10 ms cycle; enc_i = wheel revolutions over the cycle ending at t, times
//                     ngear encRes (both 1 here: fractional revolutions, "-0" occurs)
//
// The authors' kinematics (their simulateRobot_omni4.m) map the wheel displacements
// d_i = pi D_i enc_i / (ngear encRes) to the body step with
//   dx = ( d1 - d2 + d3 - d4) / 4,   dy = (-d1 - d2 + d3 + d4) / 4,
//   dtheta = -(d1 + d2 + d3 + d4) / (2 (L1 + L2)),
// the pseudo-inverse of the inverse kinematics d = W (dx, dy, dtheta) with rows
//   W_1 = [1, -1, -K],  W_2 = [-1, -1, -K],  W_3 = [1, 1, -K],  W_4 = [-1, 1, -K],  K = (L1+L2)/2
// (W^T W = diag(4, 4, 4 K^2), so pinv(W) = W^T / diag(4, 4, 4 K^2) is the matrix above).
// A translation part of norm sqrt(2) is a Swedish wheel with 45 deg rollers (omni_kinematics.h:
// row = [cos(phi + gamma), sin(phi + gamma), x sin(phi + gamma) - y cos(phi + gamma)] / (r cos
// gamma) for a wheel at (x, y) driven along phi), i.e. the robot is kinematically a mecanum
// robot. Solving each row for a wheel at (+-L1/2, +-L2/2):
//   wheel 1 = fl at ( L1/2,  L2/2), driven along   0 deg, rollers -45 deg:  [ 1, -1, -K]
//   wheel 2 = fr at ( L1/2, -L2/2), driven along 180 deg, rollers +45 deg:  [-1, -1, -K]
//   wheel 3 = rl at (-L1/2,  L2/2), driven along   0 deg, rollers +45 deg:  [ 1,  1, -K]
//   wheel 4 = rr at (-L1/2, -L2/2), driven along 180 deg, rollers -45 deg:  [-1,  1, -K]
// (the right-hand motors turn the other way: a positive count drives the robot backwards), and
// our wheel rate is the recorded count with its own sign: w_i = 2 pi enc_i / (ngear encRes dt).
// Regressing the ground truth's body steps on the counts confirms the pattern (translation
// 0.27 per pair instead of 0.25, yaw 1.28 instead of 1.25 per metre of wheel travel); an omni
// wheel X layout (0.35) does not fit. The importer checks the layout against the ground truth
// (tools/import_channel_order.h, the one channel-order check) and refuses to write when another
// wheel order or sign fits far better.
//
// Two sessions (square/231220200521, square/231220200550) declare L1, L2 = 0.205, 0.215 m: the
// authors perturbed their starting values; the robot is the same. The nominal robot takes each
// metadata value that most sessions declare.

#include <array>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/run_log.h"
#include "tools/optiodom_format.h"

namespace fitcal::tools {

struct OptiOdomOmni4Metadata {
  double gear_ratio = 0.0;              // ngear
  double encoder_counts_per_rev = 0.0;  // encRes
  std::array<double, 2> length_m{};     // L1, L2
  std::array<double, 4> diameter_m{};   // D1..D4
  int num_runs = 0;                     // N
  double CountsPerWheelRev() const { return gear_ratio * encoder_counts_per_rev; }
  bool operator==(const OptiOdomOmni4Metadata& o) const {
    return gear_ratio == o.gear_ratio && encoder_counts_per_rev == o.encoder_counts_per_rev &&
           length_m == o.length_m && diameter_m == o.diameter_m;
  }
};

// Runs as wheel rates in rad/s, wheels fl, fr, rl, rr.
using OptiOdomOmni4Session = optiodom::Session<OptiOdomOmni4Metadata, RunLog>;

// Reads one session directory (runs in parallel, numbers by std::from_chars); throws
// io::InputError naming the file and line.
OptiOdomOmni4Session ReadOptiOdomOmni4Session(const std::string& directory);

// The nominal `omni` robot of this metadata: the layout above, r_i = D_i / 2, bounds R +- 0.025
// m, r +- 15 %, delta +- 5 deg (wider than Palacin Eq. 16; the .cc says why).
RobotModelPtr OptiOdomOmni4NominalModel(const OptiOdomOmni4Metadata& metadata);

struct Omni4ImportResult {
  int num_sessions = 0;
  int num_runs = 0;
  std::string channel_order;       // the channel-order check's line (tools/import_channel_order.h)
  double nominal_mean_cf = 0.0;    // mean over runs of |final-pose residual| (Eq. 14)
  std::vector<std::string> notes;  // e.g. sessions that declare perturbed nominal values
};

// Reads the sessions, checks the layout, and writes <out>/dataset.yaml, <out>/robot.yaml (the
// nominal omni robot) and per run runs/<id>_encoders.csv (`t,w_fl,w_fr,w_rl,w_rr`, rad/s over the
// interval ending at t) and runs/<id>_ground_truth.csv (`t,x,y,theta`). Throws io::InputError for
// bad input and MiswiredError when the channel-order check fails (nothing is written then).
Omni4ImportResult ImportOptiOdomOmni4(const std::vector<std::string>& session_dirs,
                                      const std::string& out_dir, bool force = false,
                                      bool skip_mapping_check = false);

}  // namespace fitcal::tools
