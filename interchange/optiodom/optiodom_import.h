#pragma once
// The import of `fitcal import optiodom <session-dir>... --out <dataset-dir>` (the command only
// reads its flags, calls ImportOptiOdom and prints): the published OptiOdom recordings (Sousa et
// al., J. Intell. Robot. Syst. 105, 39, 2022; MIT licence; optiodom_format.h) of any robot of the
// study into a fitcal data set, by one sequence for every robot (ImportOptiOdom below); what
// differs per robot is data in interchange/optiodom/optiodom_robots.h.

#include <functional>
#include <string>
#include <vector>

#include "fit/final_pose_errors.h"
#include "models/model_interface.h"
#include "odometry/run_log.h"
#include "interchange/optiodom/optiodom_format.h"

namespace fitcal::optiodom {

struct RobotKind;  // interchange/optiodom/optiodom_robots.h

struct ImportOptiOdomOptions {
  std::vector<std::string> sessions;
  std::string out;
  bool force = false;               // overwrite an existing data set
  bool skip_mapping_check = false;  // write even if another wheel mapping fits better
};

// What an import read, checked and wrote.
struct OptiOdomImport {
  const optiodom::RobotKind* kind = nullptr;  // the sessions' robot
  RobotModelPtr model;                        // the nominal robot, as robot.yaml holds it
  int num_sessions = 0;
  std::vector<optiodom::RunRows> rows;  // the run files (our signs; empty unless ticks), ...
  std::vector<RunLog> runs;             // ... and as written: wheel rates, labels
  std::vector<std::string> notes;       // sessions declaring other values, runs left out
  std::string channel_order;            // the channel-order check's line
  FinalPoseErrors nominal;              // Palacin Eq. 14 over the runs at the nominal
};

// Reads and checks the sessions (one robot), nothing written and no channel-order check: the
// model, the runs and the notes. Throws io::InputError (file, line, cause).
OptiOdomImport ReadOptiOdomSessions(const std::vector<std::string>& session_dirs);

// The whole import: the sessions checked to be one robot's and inputs that `out` may not replace,
// read, checked and written. Hands `say` the notes and then the channel-order check's line as they
// are found (printed before a refusal, as a command prints them). Throws UsageError for sessions
// of two robots or an `out` it may not write, io::InputError for bad input and MiswiredError
// (diagnosis/miswired_error.h) when the channel-order check fails; nothing is written then.
OptiOdomImport ImportOptiOdom(const ImportOptiOdomOptions& options,
                              const std::function<void(const std::string&)>& say = nullptr);

// The line that ends an import: what it wrote and the runs' nominal CF.
std::string ImportSummary(const OptiOdomImport& import, const std::string& out);

}  // namespace fitcal::optiodom
