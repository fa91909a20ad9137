#include "tools/fleet_command.h"

#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <regex>
#include <stdexcept>

#include "io/calibration_yaml.h"
#include "io/input_error.h"
#include "io/report_json.h"
#include "io/yaml_reader.h"
#include "models/model_registry.h"
#include "odometry/text_format.h"
#include "io/command_failure.h"
#include "tools/dataset_command.h"

namespace fitcal::tools {
namespace {

namespace fs = std::filesystem;

// A calibration further than this many robust sigmas from the robot's median is an outlier
// (a Gaussian value lies beyond 5 sigma once in 1.7 million).
constexpr double kOutlierRobustZ = 5.0;
constexpr std::size_t kMinForOutlier = 5;
// A slope this many standard errors from zero is a trend (|t| > 3: p < 0.01 for n >= 6).
constexpr double kTrendT = 3.0;
constexpr std::size_t kMinForTrend = 4;
constexpr const char* kCfRow = "cf_validation_after";

// One row's value in one calibration: SI units and rad, printed in `unit` (value x scale).
struct FleetValue {
  std::string name, unit;
  double value = 0.0, display_scale = 1.0;
  double sigma = std::numeric_limits<double>::quiet_NaN();  // as recorded; NaN when not
};

struct Calibration {
  std::string file, robot, date;
  std::vector<FleetValue> values;
  // Which runs judged its held-out CF: the data set and the split it was fitted with. Two
  // calibrations with different keys report CFs of different runs.
  std::string judged_on;
  std::string model;  // "" for a metrics.json, which does not name it
};

constexpr const char* kCfUnit = "Eq. 14";

// The data set and the training split a calibration's provenance records; "" without one.
std::string JudgedOn(const std::optional<io::CalibrationProvenance>& p) {
  if (!p) return "";
  std::string reps;
  for (int r : p->training_repetitions) reps += (reps.empty() ? "" : ",") + std::to_string(r);
  return p->dataset + " (training " +
         (p->training_trajectories.empty() ? "repetitions " + reps
                                           : "trajectories " + p->training_trajectories) +
         ")";
}

// Days since 1970-01-01 of a proleptic Gregorian YYYY-MM-DD (Howard Hinnant's days_from_civil).
long DaysFromCivil(int y, int m, int d) {
  y -= m <= 2;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const long yoe = y - era * 400;
  const long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

long Days(const std::string& date) {
  return DaysFromCivil(std::stoi(date.substr(0, 4)), std::stoi(date.substr(5, 2)),
                       std::stoi(date.substr(8, 2)));
}

std::string DateOf(const std::string& path) {
  static const std::regex kDate("(19|20)[0-9]{2}-(0[1-9]|1[0-2])-(0[1-9]|[12][0-9]|3[01])");
  std::smatch m;
  if (!std::regex_search(path, m, kDate)) {
    throw io::InputError(io::InputErrorKind::kBadPath, path, 0,
                         "no date (YYYY-MM-DD) in its path; fleet dates each calibration by its "
                         "path, e.g. robots/r1/2026-05-01/cal.yaml");
  }
  return m.str();
}

Calibration ReadCalibration(const std::string& path) {
  const YAML::Node root = io::LoadYamlFile(path);
  const RobotModelPtr model = ReadRobotModel(root, path);
  Calibration c;
  c.file = path;
  c.robot = model->robot().name;
  c.model = model->robot().model;
  c.date = DateOf(path);
  const Robot& robot = model->robot();
  const std::optional<io::CalibrationProvenance> provenance = io::ReadCalibrationProvenance(path);
  const std::vector<double> sigma =
      provenance ? io::RecordedSigmas(*provenance, robot.parameters) : std::vector<double>{};
  for (std::size_t k = 0; k < robot.parameters.size(); ++k) {
    const ParameterInfo& info = robot.parameters[k];
    c.values.push_back({info.name, info.DisplayUnit(), robot.nominal[k], info.DisplayScale(),
                        sigma.empty() ? std::numeric_limits<double>::quiet_NaN() : sigma[k]});
  }
  const YAML::Node cf = root["calibration"]["cf_validation"];
  if (cf && cf.IsMap() && cf["after"]) {
    c.values.push_back(
        {kCfRow, kCfUnit, io::YamlDouble(cf["after"], path, "calibration.cf_validation"), 1.0,
         std::numeric_limits<double>::quiet_NaN()});
    c.judged_on = JudgedOn(provenance);
  }
  return c;
}

// A report's metrics.json (tools/report_command.h): the robot, each parameter's calibrated value
// (key calibrated_<unit>; degrees turned to radians, as the model holds angles) and the held-out
// CF of "all validation runs". JSON is YAML: yaml-cpp reads it.
Calibration ReadMetricsJson(const std::string& path) {
  const YAML::Node root = io::LoadYamlFile(path);
  Calibration c;
  c.file = path;
  c.date = DateOf(path);
  if (!root.IsMap() || !root["robot"] || !root["parameters"].IsSequence()) {
    throw io::InputError(io::InputErrorKind::kMissingKey, path, 1,
                         "not a fitcal report's metrics.json (robot, parameters)");
  }
  // Version 1 had no key; a later layout may have moved the parameters (docs/metrics_json.md):
  // read only the versions whose keys this fleet knows, never a file it would half-read.
  const YAML::Node version = root["version"];
  const std::string current = std::to_string(io::kMetricsJsonVersion);
  const bool known =
      !version || (version.IsScalar() && (version.Scalar() == "1" || version.Scalar() == current));
  if (!known) {
    throw io::InputError(io::InputErrorKind::kBadValue, path, version.Mark().line + 1,
                         "metrics.json version " + (version.IsScalar() ? version.Scalar() : "?") +
                             " is not one this fitcal reads (1 to " + current +
                             "); read it with the fitcal that wrote it");
  }
  c.robot = root["robot"].as<std::string>();
  for (const YAML::Node& p : root["parameters"]) {
    for (const auto& kv : p) {
      const std::string key = kv.first.as<std::string>();
      if (key.rfind("calibrated_", 0) != 0) continue;
      const double v = io::YamlDouble(kv.second, path, "parameters." + key);
      const bool degrees = key.size() > 4 && key.compare(key.size() - 4, 4, "_deg") == 0;
      const double scale = degrees ? 180.0 / M_PI : 1.0;
      double sigma = std::numeric_limits<double>::quiet_NaN();
      if (p["sigma"] && p["sigma"].IsScalar() && p["sigma"].Scalar() != "null") {
        sigma = io::YamlDouble(p["sigma"], path, "parameters.sigma") / scale;
      }
      c.values.push_back(
          {p["name"].as<std::string>(), degrees ? "deg" : "m", v / scale, scale, sigma});
    }
  }
  for (const YAML::Node& g : root["summary"]) {
    if (g["group"] && g["group"].as<std::string>() == "all validation runs" && g["after"]) {
      c.values.push_back(
          {kCfRow, kCfUnit, io::YamlDouble(g["after"]["cf"], path, "summary.after.cf"), 1.0,
           std::numeric_limits<double>::quiet_NaN()});
      // A report judges on the runs of the data set it was given.
      c.judged_on = root["dataset"] && root["dataset"].IsScalar()
                        ? root["dataset"].Scalar() + " (report)"
                        : path;
    }
  }
  return c;
}

bool IsMetricsJson(const fs::path& p) { return p.filename() == "metrics.json"; }

bool IsCalibrationYaml(const fs::path& p) {
  if (p.extension() != ".yaml" && p.extension() != ".yml") return false;
  try {
    return static_cast<bool>(YAML::LoadFile(p.string())["calibration"]);
  } catch (const YAML::Exception&) {
    return false;  // not ours to judge when found by searching
  }
}

std::vector<std::string> Files(const std::vector<std::string>& inputs) {
  std::vector<std::string> files;
  for (const std::string& in : inputs) {
    if (!fs::is_directory(in)) {
      files.push_back(in);
      continue;
    }
    for (const auto& e : fs::recursive_directory_iterator(in)) {
      if (e.is_regular_file() && (IsCalibrationYaml(e.path()) || IsMetricsJson(e.path()))) {
        files.push_back(e.path().string());
      }
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void FlagOutliers(FleetSeries* s) {
  if (s->values.size() < kMinForOutlier) return;
  const double median = Median(s->values);
  std::vector<double> deviation;
  for (double v : s->values) deviation.push_back(std::abs(v - median));
  const double sigma = 1.4826 * Median(deviation);
  if (!(sigma > 0.0)) return;
  for (std::size_t i = 0; i < s->values.size(); ++i) {
    if (std::abs(s->values[i] - median) > kOutlierRobustZ * sigma) {
      s->outliers.push_back(s->dates[i]);
    }
  }
}

// Ordinary least squares of value on days, outliers left out (one bad night is not a trend).
void FlagTrend(FleetSeries* s) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < s->values.size(); ++i) {
    if (std::find(s->outliers.begin(), s->outliers.end(), s->dates[i]) != s->outliers.end()) {
      continue;
    }
    x.push_back(static_cast<double>(Days(s->dates[i])));
    y.push_back(s->values[i]);
  }
  const std::size_t n = x.size();
  if (n < kMinForTrend) return;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) mx += x[i] / n, my += y[i] / n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  if (!(sxx > 0)) return;
  const double slope = sxy / sxx;
  double rss = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = y[i] - my - slope * (x[i] - mx);
    rss += r * r;
  }
  const double scatter = std::sqrt(rss / static_cast<double>(n - 2));
  const double standard_error = scatter / std::sqrt(sxx);
  const double span_days = *std::max_element(x.begin(), x.end()) - *std::min_element(x.begin(), x.end());
  s->slope_per_30_days = 30.0 * slope;
  s->has_slope = true;
  s->trend = std::abs(slope) > kTrendT * standard_error &&
             std::abs(slope) * span_days > scatter;
}

// A robot is its name: two calibrations of one name and different models are two robots
// (a renamed copy, a rebuilt robot), whose parameters must not be merged into one series.
void RefuseOneNameForTwoModels(const std::vector<Calibration>& all) {
  std::map<std::string, const Calibration*> first_of;
  for (const Calibration& c : all) {
    if (c.model.empty()) continue;
    const auto [it, inserted] = first_of.emplace(c.robot, &c);
    if (!inserted && it->second->model != c.model) {
      throw io::InputError(io::InputErrorKind::kBadValue, c.file, 0,
                           "robot '" + c.robot + "' is a " + c.model + " here and a " +
                               it->second->model + " in " + it->second->file +
                               "; fleet keeps one series per robot name: give the robots "
                               "different names");
    }
  }
}

}  // namespace

std::vector<FleetSeries> ReadFleet(const std::vector<std::string>& inputs) {
  std::vector<Calibration> all;
  for (const std::string& f : Files(inputs)) {
    all.push_back(IsMetricsJson(f) ? ReadMetricsJson(f) : ReadCalibration(f));
  }
  if (all.empty()) throw UsageError("no calibrated YAML found in the inputs");
  RefuseOneNameForTwoModels(all);
  std::stable_sort(all.begin(), all.end(), [](const Calibration& a, const Calibration& b) {
    return std::tie(a.robot, a.date) < std::tie(b.robot, b.date);
  });
  std::vector<FleetSeries> out;
  std::map<std::pair<std::string, std::string>, std::size_t> index;
  for (const Calibration& c : all) {
    for (const FleetValue& v : c.values) {
      const auto key = std::make_pair(c.robot, v.name);
      auto it = index.find(key);
      if (it == index.end()) {
        it = index.emplace(key, out.size()).first;
        FleetSeries s;
        s.robot = c.robot;
        s.parameter = v.name;
        s.unit = v.unit;
        s.display_scale = v.display_scale;
        out.push_back(std::move(s));
      }
      FleetSeries& s = out[it->second];
      // A calibration and its report (metrics.json) on the same date are one result.
      if (!s.dates.empty() && s.dates.back() == c.date) continue;
      s.dates.push_back(c.date);
      s.values.push_back(v.value);
      s.sigmas.push_back(v.sigma);
      s.files.push_back(c.file);
      if (v.name == kCfRow) s.judged_on.push_back(c.judged_on);
    }
  }
  for (FleetSeries& s : out) {
    FlagOutliers(&s);
    FlagTrend(&s);
  }
  return out;
}

// The note under a robot's table when its held-out CFs were judged on different runs: a change
// in CF may then be the runs', not the robot's.
std::string DifferentJudgesNote(const FleetSeries& s) {
  std::vector<std::string> distinct;
  for (const std::string& j : s.judged_on) {
    if (std::find(distinct.begin(), distinct.end(), j) == distinct.end()) distinct.push_back(j);
  }
  if (distinct.size() < 2) return "";
  std::string note = "  note: " + std::string(kCfRow) + " was judged on " +
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
                     sigma.c_str(), k * Median(s.values), slope.c_str(), flags.c_str());
    if (s.parameter == kCfRow) note += DifferentJudgesNote(s);
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
