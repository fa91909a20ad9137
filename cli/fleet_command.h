#pragma once
// `fitcal fleet <calibrated YAMLs or directories>`: results across robots and time. Reads many
// calibrated robot YAMLs (one per robot and date, as a fleet's nightly jobs write them: the date
// is the first YYYY-MM-DD in the file's path, the robot the YAML's `name`), and prints per robot
// one row per parameter (and the held-out CF the calibration recorded): the number of
// calibrations, the first and last date and value, the median, and the outlier and trend flags
// (validation/fleet_statistics.h decides them).
// Directories are searched recursively for *.yaml files that hold a `calibration:` block and for
// reports' metrics.json (robot, calibrated parameters, held-out CF); a calibration and its report
// of one robot and date count once.

#include <string>
#include <vector>

#include "validation/fleet_statistics.h"

namespace CLI {
class App;
}

namespace fitcal::tools {

struct FleetOptions {
  std::vector<std::string> inputs;
};

// The table, one block per robot.
std::string FleetTable(const std::vector<FleetSeries>& series);

void AddFleetOptions(CLI::App& app, FleetOptions& options);
// 0 printed (flags are findings, not errors); 1 bad input; 2 bad options.
int RunFleetCommand(const FleetOptions& options);

}  // namespace fitcal::tools
