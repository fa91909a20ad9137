#include "interchange/fleet/fleet_files.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <regex>
#include <set>

#include "fit/run_split.h"
#include "io/calibration_yaml.h"
#include "io/command_failure.h"
#include "io/input_error.h"
#include "io/warnings.h"
#include "io/yaml_reader.h"
#include "models/model_registry.h"
#include "pages/report_json.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;

using Calibration = FleetCalibration;
constexpr const char* kCfRow = kFleetCfRow;
constexpr const char* kCfUnit = "Eq. 14";

// The data set and the training split that chose a calibration's held-out runs, in words.
std::string JudgedOn(const std::string& dataset, const std::vector<int>& training_repetitions,
                     const std::string& training_trajectories) {
  std::string reps;
  for (int r : training_repetitions) reps += (reps.empty() ? "" : ",") + std::to_string(r);
  return dataset + " (training " +
         (training_trajectories.empty() ? "repetitions " + reps
                                        : "trajectories " + training_trajectories) +
         ")";
}

// As a calibration's provenance records them; "" without one.
std::string JudgedOn(const std::optional<io::CalibrationProvenance>& p) {
  return p ? JudgedOn(p->dataset, p->training_repetitions, p->training_trajectories) : "";
}

// A report that found the calibration's training runs in its data set by id (training_source "...
// recorded by id (repetitions 1-5)") judged the runs the calibration's record names as held out:
// said as the calibration says it, so that the two are one set of runs, not "2 different sets".
std::string JudgedOnOfReport(const YAML::Node& root, const std::string& path) {
  const std::string dataset = root["dataset"] && root["dataset"].IsScalar()
                                  ? root["dataset"].Scalar() : path;
  const YAML::Node source = root["training_source"], reps = root["training_repetitions"];
  if (source && source.IsScalar() && source.Scalar().find("recorded by id") != std::string::npos &&
      reps && reps.IsScalar()) {
    try {
      return JudgedOn(dataset, ParseRepetitionList(reps.Scalar()), "");
    } catch (const std::exception&) {
      // not a list fitcal wrote: the report's own words below
    }
  }
  return dataset + " (report)";
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
  const std::optional<io::CalibrationProvenance> provenance =
      io::ReadCalibrationProvenance(root, path);
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

// A report's metrics.json (cli/report_command.h): the robot, each parameter's calibrated value
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
  const std::set<std::string> readable = {"1", "2", current};  // 3 moved `sigma` to SI, see below
  const bool known = !version || (version.IsScalar() && readable.count(version.Scalar()) == 1);
  if (!known) {
    throw io::InputError(io::InputErrorKind::kBadValue, path, version.Mark().line + 1,
                         "metrics.json version " + (version.IsScalar() ? version.Scalar() : "?") +
                             " is not one this fitcal reads (1 to " + current +
                             "); read it with the fitcal that wrote it");
  }
  c.robot = root["robot"].as<std::string>();
  std::set<std::string> names;  // a parameter listed twice has no one value to chart
  for (const YAML::Node& p : root["parameters"]) {
    const std::string name = io::YamlString(p["name"], path, "parameters.name");
    if (!names.insert(name).second) {
      throw io::InputError(io::InputErrorKind::kBadValue, path, p.Mark().line + 1,
                           "parameter '" + name + "' is listed twice (which value is it?)");
    }
    for (const auto& kv : p) {
      const std::string key = kv.first.as<std::string>();
      if (key.rfind("calibrated_", 0) != 0) continue;
      const double v = io::YamlDouble(kv.second, path, "parameters." + key);
      const bool degrees = key.size() > 4 && key.compare(key.size() - 4, 4, "_deg") == 0;
      const double scale = degrees ? 180.0 / M_PI : 1.0;
      // sigma_<unit> beside calibrated_<unit>, in every version (`sigma` turned SI in 3).
      const std::string sigma_key = "sigma_" + key.substr(std::string("calibrated_").size());
      double sigma = std::numeric_limits<double>::quiet_NaN();
      if (p[sigma_key] && p[sigma_key].IsScalar() && p[sigma_key].Scalar() != "null") {
        sigma = io::YamlDouble(p[sigma_key], path, "parameters." + sigma_key) / scale;
      }
      c.values.push_back({name, degrees ? "deg" : "m", v / scale, scale, sigma});
    }
  }
  for (const YAML::Node& g : root["summary"]) {
    if (g["group"] && g["group"].as<std::string>() == "all validation runs" && g["after"]) {
      c.values.push_back(
          {kCfRow, kCfUnit, io::YamlDouble(g["after"]["cf"], path, "summary.after.cf"), 1.0,
           std::numeric_limits<double>::quiet_NaN()});
      c.judged_on = JudgedOnOfReport(root, path);
    }
  }
  if (c.values.empty()) {
    throw io::InputError(io::InputErrorKind::kMissingKey, path, 1,
                         "a metrics.json without a calibrated parameter or a held-out CF: "
                         "nothing of it to chart");
  }
  return c;
}

bool IsMetricsJson(const fs::path& p) { return p.filename() == "metrics.json"; }

bool IsCalibrationYaml(const fs::path& p) {
  if (p.extension() != ".yaml" && p.extension() != ".yml") return false;
  try {
    return static_cast<bool>(YAML::LoadFile(p.string())["calibration"]);
  } catch (const YAML::Exception& e) {
    // Not ours to refuse when found by searching (a directory may hold other YAML), but a
    // calibration a write cut short looks just like this: said, so that no night is lost unseen.
    io::Warn(p.string(), e.mark.is_null() ? 0 : e.mark.line + 1,
             "does not parse as YAML (" + e.msg + "); skipped by the search");
    return false;
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

}  // namespace

std::vector<FleetSeries> ReadFleet(const std::vector<std::string>& inputs) {
  std::vector<Calibration> all;
  for (const std::string& f : Files(inputs)) {
    all.push_back(IsMetricsJson(f) ? ReadMetricsJson(f) : ReadCalibration(f));
  }
  if (all.empty()) throw UsageError("no calibrated YAML found in the inputs");
  return FleetSeriesOf(std::move(all));
}

}  // namespace fitcal
