#pragma once
// `fitcal fleet <calibrated YAMLs or directories>`: results across robots and time. Reads many
// calibrated robot YAMLs (one per robot and date, as a fleet's nightly jobs write them: the date
// is the first YYYY-MM-DD in the file's path, the robot the YAML's `name`), and prints per robot
// one row per parameter (and the held-out CF the calibration recorded): the number of
// calibrations, the first and last date and value, the median, and flags:
//   outlier  a calibration more than kOutlierRobustZ robust sigmas (1.4826 x the median absolute
//            deviation) from the robot's median of that parameter (needs >= 5 calibrations);
//   trend    a least-squares line over the dates whose slope is kTrendT standard errors from 0
//            and moves the value by more than the scatter about the line over the span (needs
//            >= 4 calibrations): a wheel wearing, a radius shrinking over weeks.
// Directories are searched recursively for *.yaml files that hold a `calibration:` block and for
// reports' metrics.json (robot, calibrated parameters, held-out CF); a calibration and its report
// of one robot and date count once.

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace fitcal::tools {

struct FleetOptions {
  std::vector<std::string> inputs;
};

// One parameter of one robot over its calibrations, in date order.
struct FleetSeries {
  std::string robot, parameter;
  std::string unit;                // printed unit: "m", "deg", or "Eq. 14" for the held-out CF
  double display_scale = 1.0;      // printed value = value x display_scale (rad -> deg)
  std::vector<std::string> dates;  // YYYY-MM-DD
  std::vector<double> values;      // SI units and rad, as the model holds them
  std::vector<double> sigmas;      // one sigma each calibration recorded (SI, rad); NaN: none
  std::vector<std::string> files;
  // The held-out CF's row only: the data set and split that judged each calibration.
  std::vector<std::string> judged_on;
  std::vector<std::string> outliers;  // dates of the flagged calibrations
  bool trend = false;
  bool has_slope = false;  // enough calibrations (kMinForTrend) for a line
  double slope_per_30_days = 0.0;
};

// Reads every input; throws io::InputError for a bad file or a path without a date,
// std::invalid_argument when no calibration is found. Series sorted by robot, then in the
// model's parameter order.
std::vector<FleetSeries> ReadFleet(const std::vector<std::string>& inputs);

// The table, one block per robot.
std::string FleetTable(const std::vector<FleetSeries>& series);

void AddFleetOptions(CLI::App& app, FleetOptions& options);
// 0 printed (flags are findings, not errors); 1 bad input; 2 bad options.
int RunFleetCommand(const FleetOptions& options);

}  // namespace fitcal::tools
