#pragma once
// `fitcal import optiodom <session-dir>... --out <dataset-dir>`: converts the published OptiOdom
// recordings (Sousa et al., "OptiOdom: a Generic Approach for Odometry Calibration of Wheeled
// Mobile Robots", J. Intell. Robot. Syst. 105, 39, 2022; MIT licence) into a fitcal data set:
// per-run encoder + ground-truth CSVs, dataset.yaml and a nominal robot YAML. The command picks
// the robot by the sessions' metadata `type` (omni3 here; omni4, diff and tricyc in their
// import_optiodom_*.h); every robot reads and writes through tools/optiodom_format.h.
//
// The omni3 robot:
// Published format, per session directory <s>/:
//   <s>_metadata.csv  rows `key,v1,v2,...`: type (omni3), ngear, encRes, Li (m), Di (m, three),
//                     N (runs), gt_ti/gt_tf/odo_ti/odo_tf (clock-mapping instants per run)
//   <s>_run-NN.csv    no header, `t_s, x_gt_m, y_gt_m, theta_gt_rad, ticks_1, ticks_2, ticks_3`,
//                     ticks = increments over the 40 ms cycle ending at t
//
// Wheel convention. The authors' kinematics put wheels 1, 2, 3 at 300, 60, 180 deg with drive
// directions phi = -150, -30, 90 deg and wheel_disp_i = cos(phi_i) dx + sin(phi_i) dy - L dtheta.
// Ours (Palacin Eq. 1) is w_i r_i = -sin(delta_i) vx + cos(delta_i) vy + R_i omega; with
// delta_i = (300, 60, 180) deg, -sin(delta_i) = -cos(phi_i) and cos(delta_i) = -sin(phi_i), so our
// wheel a, b, c is the authors' 1, 2, 3 with the sign of the ticks flipped:
//   ticks_a = -ticks_1,  ticks_b = -ticks_2,  ticks_c = -ticks_3.
// The importer verifies this numerically (tools/import_channel_order.h, the one channel-order
// check) and refuses to write a data set whose ground truth another wheel order/sign explains far
// better.

#include <array>
#include <string>
#include <vector>

#include "models/omni3/omni3_robot.h"
#include "odometry/run_log.h"
#include "tools/optiodom_format.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

struct OptiOdomMetadata {
  std::string type;
  double gear_ratio = 0.0;                                   // ngear
  double encoder_counts_per_rev = 0.0;                       // encRes (counts per motor revolution)
  double distance_m = 0.0;                                   // Li
  std::array<double, 3> diameter_m{};                        // Di
  int num_runs = 0;                                          // N
  std::vector<double> gt_ti_s, gt_tf_s, odo_ti_s, odo_tf_s;  // clock mapping per run
  double TicksPerWheelRev() const { return gear_ratio * encoder_counts_per_rev; }
};

// One run in our convention: encoder[k] = ticks of wheels a, b, c over (t(k-1), t(k)], already
// mapped from the authors' (see above).
using OptiOdomRun = optiodom::RunRows;

using OptiOdomSession = optiodom::Session<OptiOdomMetadata, OptiOdomRun>;

// Reads and checks one session directory; throws io::InputError (file, line, cause).
OptiOdomSession ReadOptiOdomSession(const std::string& directory);

// The nominal robot of a session: R = Li, r = Di / 2, delta = (300, 60, 180) deg, bounds as
// Palacin Eq. 16 scaled to this robot (R +- 0.025 m, r +- 6.8 %, delta +- 2 deg), encoder ticks
// per wheel revolution = ngear * encRes.
Omni3Robot OptiOdomNominalRobot(const OptiOdomMetadata& metadata);

// The run as fitcal replays it (wheel rates from the ticks, ground truth on the same clock).
RunLog OptiOdomRunLog(const OptiOdomSession& session, const OptiOdomRun& run);

struct ImportOptiOdomOptions {
  std::vector<std::string> sessions;
  std::string out;
  bool force = false;               // overwrite an existing data set
  bool skip_mapping_check = false;  // write even if another wheel mapping fits better
};

// Declares every flag of `import optiodom` on its subcommand `app`, bound to `options`.
void AddImportOptiOdomOptions(CLI::App& app, ImportOptiOdomOptions& options);

int RunImportOptiOdomCommand(const ImportOptiOdomOptions& options);

}  // namespace fitcal::tools
