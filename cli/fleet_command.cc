#include "cli/fleet_command.h"

#include <CLI/CLI.hpp>
#include <iostream>

#include "cli/dataset_command.h"
#include "interchange/fleet/fleet_files.h"
#include "odometry/text_format.h"

namespace fitcal::tools {

// The note under a robot's table when its held-out CFs were judged on different runs: a change
// in CF may then be the runs', not the robot's.
std::string DifferentJudgesNote(const FleetSeries& s) {
  const std::vector<std::string>& distinct = s.distinct_judges;
  if (distinct.size() < 2) return "";
  std::string note = "  note: " + std::string(kFleetCfRow) + " was judged on " +
                     std::to_string(distinct.size()) +
                     " different sets of held-out runs, so its values do not compare like for "
                     "like:";
  for (const std::string& j : distinct) note += "\n    " + (j.empty() ? "(not recorded)" : j);
  return note + "\n";
}

std::string FleetTable(const std::vector<FleetSeries>& series) {
  std::string out, robot, note;
  const auto close_robot = [&] {
    out += note;
    note.clear();
  };
  for (const FleetSeries& s : series) {
    if (s.robot != robot) {
      close_robot();
      robot = s.robot;
      out += StrFormat("\n%s\n  %-22s %-6s %3s  %-10s %12s  %-10s %12s %10s %12s %14s  %s\n",
                       robot.c_str(), "parameter", "unit", "n", "first", "value", "last", "value",
                       "+-1 sigma", "median", "slope/30 d", "flags");
    }
    std::string flags = s.trend ? "TREND" : "";
    for (const std::string& d : s.outliers) flags += (flags.empty() ? "" : " ") + ("OUTLIER " + d);
    const double k = s.display_scale;
    const std::string slope = s.has_slope ? StrFormat("%+.4g", k * s.slope_per_30_days) : "-";
    const std::string sigma = StrFormatFinite(s.sigmas.back(), "%.2g", k * s.sigmas.back());
    out += StrFormat("  %-22s %-6s %3zu  %-10s %12.6g  %-10s %12.6g %10s %12.6g %14s  %s\n",
                     s.parameter.c_str(), s.unit.c_str(), s.values.size(), s.dates.front().c_str(),
                     k * s.values.front(), s.dates.back().c_str(), k * s.values.back(),
                     sigma.c_str(), k * s.median, slope.c_str(), flags.c_str());
    if (s.parameter == kFleetCfRow) note += DifferentJudgesNote(s);
  }
  close_robot();
  return out;
}

void AddFleetOptions(CLI::App& app, FleetOptions& o) {
  app.add_option("inputs", o.inputs,
                 "Calibrated robot YAMLs or reports' metrics.json, or directories searched for "
                 "them (the date: the first YYYY-MM-DD in each path)")
      ->required();
  app.footer(
      "Output: per robot (the YAML's name), one row per parameter and one for the held-out CF\n"
      "(cf_validation_after, Palacin Eq. 14: final position error in m plus heading error in rad,\n"
      "lower is better). Columns: unit (m, deg; the CF in Eq. 14 units), n calibrations, the "
      "first\n"
      "and last date and value, +-1 sigma as the last calibration recorded it ('-': none), the\n"
      "median, the least-squares slope per 30 days, and flags: OUTLIER <date> (more than 5 robust\n"
      "sigmas from the robot's median, >= 5 calibrations), TREND (slope 3 standard errors from 0\n"
      "and larger than the scatter over the span, >= 4 calibrations). A note follows when a "
      "robot's\n"
      "CFs were judged on different held-out runs (data set or split): they do not compare.\n"
      "Guide: docs/ros2.md (fleet).");
}

int RunFleetCommand(const FleetOptions& o) {
  return RunReportingErrors("fitcal fleet", [&]() -> int {
    std::cout << FleetTable(ReadFleet(o.inputs)).substr(1);
    return 0;
  });
}

}  // namespace fitcal::tools
