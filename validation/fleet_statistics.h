#pragma once
// A fleet's calibrations across robots and time (`fitcal fleet`, cli/fleet_command.h, reads
// them and prints the table): per robot, one series per parameter (and the held-out CF the
// calibration recorded) in date order, and its flags:
//   outlier  a calibration more than kOutlierRobustZ robust sigmas (1.4826 x the median absolute
//            deviation) from the robot's median of that parameter (needs >= 5 calibrations);
//   trend    a least-squares line over the dates whose slope is kTrendT standard errors from 0
//            and moves the value by more than the scatter about the line over the span (needs
//            >= 4 calibrations): a wheel wearing, a radius shrinking over weeks.
// A calibration and its report of one robot and date count once. No files.

#include <limits>
#include <string>
#include <vector>

namespace fitcal {

// The series of the held-out CF (Palacin Eq. 14), beside the parameters'.
inline constexpr char kFleetCfRow[] = "cf_validation_after";

// One row's value in one calibration: SI units and rad, printed in `unit` (value x scale).
struct FleetValue {
  std::string name, unit;
  double value = 0.0, display_scale = 1.0;
  double sigma = std::numeric_limits<double>::quiet_NaN();  // as recorded; NaN when not
};

// One calibration as read (a calibrated robot YAML or a report's metrics.json).
struct FleetCalibration {
  std::string file, robot, date;  // date YYYY-MM-DD
  std::vector<FleetValue> values;
  // Which runs judged its held-out CF: the data set and the split it was fitted with. Two
  // calibrations with different keys report CFs of different runs.
  std::string judged_on;
  std::string model;  // "" for a metrics.json, which does not name it
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
  std::vector<std::string> distinct_judges;  // judged_on without repeats, first seen first
  double median = 0.0;                       // of values
  std::vector<std::string> outliers;  // dates of the flagged calibrations
  bool trend = false;
  bool has_slope = false;  // enough calibrations (kMinForTrend) for a line
  double slope_per_30_days = 0.0;
};

// Reads every input; throws io::InputError for a bad file or a path without a date,
// std::invalid_argument when no calibration is found. Series sorted by robot, then in the
// model's parameter order.
// The series of every robot (sorted by robot, then date) with their flags. Throws io::InputError
// when one robot name is two models (a renamed copy, a rebuilt robot: never one series).
std::vector<FleetSeries> FleetSeriesOf(std::vector<FleetCalibration> calibrations);

}  // namespace fitcal
