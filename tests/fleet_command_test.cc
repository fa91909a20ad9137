// `fitcal fleet`: calibrations of two robots over eight weeks. Robot r1's left wheel wears (its
// radius shrinks 0.1 mm a week, beside a night-to-night scatter of 0.02 mm): a trend; its
// separation only scatters: none. Robot r2 is stable but one night's calibration went wrong
// (radius 2 mm off): an outlier, and not a trend.

#include "cli/fleet_command.h"
#include "interchange/fleet/fleet_files.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "io/input_error.h"
#include "io/warnings.h"
#include "models/model_registry.h"
#include "tests/model_support.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {

const char* kRobotYaml = R"(model: diff_drive
name: NAME
wheels:
  - {name: right, radius_m: 0.042}
  - {name: left, radius_m: 0.042}
wheel_separation_m: 0.200
bounds: {radius_m: [0.030, 0.050], wheel_separation_m: [0.180, 0.220]}
)";

const FleetSeries& Find(const std::vector<FleetSeries>& all, const std::string& robot,
                               const std::string& parameter) {
  for (const FleetSeries& s : all) {
    if (s.robot == robot && s.parameter == parameter) return s;
  }
  throw std::runtime_error("no series " + robot + " " + parameter);
}

TEST(Fleet, FlagsTrendsAndOutliers) {
  testing::TempDir tmp;
  std::mt19937 rng(7);
  std::normal_distribution<double> scatter(0.0, 0.00002);
  for (const std::string robot : {"r1", "r2"}) {
    std::string yaml = kRobotYaml;
    yaml.replace(yaml.find("NAME"), 4, robot);
    const RobotModelPtr model = ReadRobotModel(YAML::Load(yaml), "robot.yaml");
    for (int week = 0; week < 8; ++week) {
      std::vector<double> p = {0.0420 + scatter(rng), 0.0420 + scatter(rng), 0.2 + scatter(rng)};
      if (robot == "r1") p[1] -= 0.0001 * week;
      if (robot == "r2" && week == 5) p[0] += 0.002;
      char date[32];
      std::snprintf(date, sizeof date, "2026-%02d-%02d", 3 + week / 4, 1 + 7 * (week % 4));
      const std::string block =
          "calibration:\n  training_repetitions: [1]\n  cf_validation: {before: 0.05, after: 0.01}\n";
      tmp.Write("fleet/" + robot + "/" + date + "/cal.yaml", model->RobotYaml(p, block));
    }
  }
  tmp.Write("fleet/notes.yaml", "just: notes\n");  // found by the search, not a calibration
  const std::vector<FleetSeries> all = ReadFleet({tmp.Path("fleet")});
  const FleetSeries& worn = Find(all, "r1", "r_left");
  EXPECT_EQ(worn.values.size(), 8u);
  EXPECT_TRUE(worn.trend);
  // 0.1 mm a week: -0.43 mm per 30 days, to the scatter's standard error (~0.01 mm).
  EXPECT_NEAR(worn.slope_per_30_days, -0.0001 * 30 / 7, 0.00005);
  EXPECT_TRUE(worn.outliers.empty());
  EXPECT_FALSE(Find(all, "r1", "wheel_separation").trend);
  const FleetSeries& bad_night = Find(all, "r2", "r_right");
  ASSERT_EQ(bad_night.outliers.size(), 1u);
  EXPECT_EQ(bad_night.outliers[0], "2026-04-08");
  EXPECT_FALSE(bad_night.trend);
  EXPECT_FALSE(Find(all, "r2", "r_left").trend);
  const std::string table = tools::FleetTable(all);
  EXPECT_NE(table.find("TREND"), std::string::npos) << table;
  EXPECT_NE(table.find("OUTLIER 2026-04-08"), std::string::npos) << table;
  EXPECT_NE(table.find("cf_validation_after"), std::string::npos) << table;

  // A report's metrics.json is read too; beside its calibration of the same date it counts once
  // (it holds that calibration's values: a report of another one is a second result, refused,
  // CorpusNeighbours.FleetKeepsOneResultPerRobotAndDateOrSaysWhy).
  char report[512];
  std::snprintf(report, sizeof report,
                R"({"robot": "r1", "parameters": [{"name": "r_left", "calibrated_m": %.17g},
                {"name": "wheel_separation", "calibrated_m": %.17g}],
               "summary": [{"group": "all validation runs", "after": {"cf": 0.01}}]})",
                worn.values.back(), Find(all, "r1", "wheel_separation").values.back());
  tmp.Write("fleet/r1/2026-04-22/report/metrics.json", report);
  tmp.Write("fleet/r1/2026-04-29/report/metrics.json",
            R"({"robot": "r1", "parameters": [{"name": "r_left", "calibrated_m": 0.0411}]})");
  const std::vector<FleetSeries> with_reports = ReadFleet({tmp.Path("fleet")});
  EXPECT_EQ(Find(with_reports, "r1", "r_left").values.size(), 9u);  // + 2026-04-29 only
  EXPECT_EQ(Find(with_reports, "r1", "r_left").values.back(), 0.0411);

  // A calibration a write cut short (an unclosed flow map) is skipped by the search, not refused
  // (other YAML may sit there), but said with its file and line: a lost night is not silent.
  const std::string whole = testing::ReadFileBytes(worn.files[0]);
  tmp.Write("fleet/r1/2026-05-06/cal.yaml",
            whole.substr(0, whole.find("bounds:")) + "bounds: {r: [");
  std::vector<std::string> warnings;
  io::SetWarningSinkForTests([&](const std::string& w) { warnings.push_back(w); });
  const std::vector<FleetSeries> with_cut = ReadFleet({tmp.Path("fleet")});
  io::SetWarningSinkForTests(nullptr);
  EXPECT_EQ(Find(with_cut, "r1", "r_left").values.size(), 9u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("2026-05-06/cal.yaml:"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("does not parse as YAML"), std::string::npos) << warnings[0];

  tmp.Write("undated/cal.yaml", testing::ReadFileBytes(worn.files[0]));
  EXPECT_THROW(ReadFleet({tmp.Path("undated/cal.yaml")}), io::InputError);
}

// Issue 42: fleet printed angles in rad where fit prints degrees, no sigma, and compared held-out
// CFs judged on different runs without a word. A tricycle (one angle, its steering offset) with
// sigmas recorded as fit writes them (<name>_<display unit>, display units), judged on two data
// sets: each row carries its unit, the value and sigma in it, and a note names both data sets.
TEST(Fleet, PrintsUnitsAndSigmasAndNotesCfsJudgedOnDifferentRuns) {
  testing::TempDir tmp;
  const RobotModelPtr model = testing::ExampleModel("tricycle");
  const Robot& robot = model->robot();
  std::string sigmas;
  int angle = -1;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const ParameterInfo& info = robot.parameters[k];
    if (info.unit == ParameterUnit::kAngle) angle = k;
    sigmas += (k ? ", " : "") + info.KeyName() + ": 0.0137";
  }
  ASSERT_GE(angle, 0);
  for (const std::string data : {"/data/week1", "/data/week2"}) {
    const std::string block = "calibration:\n  dataset: " + data +
                              "\n  training_repetitions: [1, 2, 3]\n  cf_validation: {before: "
                              "0.05, after: 0.01}\n  sigma: {" +
                              sigmas + "}\n";
    tmp.Write(
        "fleet/" + std::string(data == "/data/week1" ? "2026-05-01" : "2026-05-08") + "/cal.yaml",
        model->RobotYaml(robot.nominal, block));
  }
  const std::vector<FleetSeries> all = ReadFleet({tmp.Path("fleet")});
  const std::string table = tools::FleetTable(all);
  const std::string& name = robot.parameters[angle].name;
  const FleetSeries& steering = Find(all, robot.name, name);
  EXPECT_EQ(steering.unit, "deg");
  ASSERT_EQ(steering.sigmas.size(), 2u);
  EXPECT_NEAR(steering.sigmas.back(), 0.0137 * M_PI / 180.0, 1e-15);  // held in rad
  char row[128];
  std::snprintf(row, sizeof row, "%-22s %-6s %3d  %-10s %12.6g", name.c_str(), "deg", 2,
                "2026-05-01", robot.nominal[angle] * 180.0 / M_PI);
  EXPECT_NE(table.find(row), std::string::npos) << row << "\n" << table;
  EXPECT_NE(table.find(" 0.014 "), std::string::npos) << table;  // the sigma, %.2g, in deg
  EXPECT_NE(table.find("cf_validation_after    Eq. 14"), std::string::npos) << table;
  EXPECT_NE(table.find("judged on 2 different sets of held-out runs"), std::string::npos) << table;
  EXPECT_NE(table.find("/data/week1 (training repetitions 1,2,3)"), std::string::npos) << table;

  // Judged on the same runs: no note.
  testing::TempDir same;
  for (const char* date : {"2026-05-01", "2026-05-08"}) {
    same.Write(std::string("fleet/") + date + "/cal.yaml",
               model->RobotYaml(robot.nominal,
                                "calibration:\n  dataset: /data/one\n  training_repetitions: [1]\n"
                                "  cf_validation: {before: 0.05, after: 0.01}\n"));
  }
  EXPECT_EQ(tools::FleetTable(ReadFleet({same.Path("fleet")})).find("note:"),
            std::string::npos);

  // A report a week later of the 2026-05-01 calibration on its own data set found its training
  // runs by id: the same held-out runs (it said "2 different sets": "/data/one (report)").
  const std::string key = std::string("calibrated_") + robot.parameters[0].DisplayUnit();
  same.Write("fleet/2026-05-15/rep/metrics.json",
             "{\"version\": 3, \"robot\": \"" + robot.name + "\", \"dataset\": \"/data/one\", "
             "\"training_source\": \"20 runs of this data set, recorded by id (repetitions 1)\", "
             "\"training_repetitions\": \"1\", \"parameters\": [{\"name\": \"" +
                 robot.parameters[0].name + "\", \"" + key + "\": 0.5}], \"summary\": "
             "[{\"group\": \"all validation runs\", \"after\": {\"cf\": 0.01}}]}");
  EXPECT_EQ(tools::FleetTable(ReadFleet({same.Path("fleet")})).find("note:"),
            std::string::npos);
}

// A version-3 report's angle: value and sigma in rad under "value"/"sigma", degrees under the
// _deg keys; the fleet holds rad either way (reading "sigma" as degrees, as version 2 wrote it,
// would make the 0.5 deg sigma 0.0087 deg).
TEST(Fleet, ReadsAnAngleFromAVersionThreeReport) {
  testing::TempDir tmp;
  tmp.Write("fleet/r1/2026-06-01/report/metrics.json",
            R"({"version": 3, "robot": "r1", "parameters": [{"name": "steering_offset",
            "calibrated_deg": 2, "sigma_deg": 0.5, "unit": "rad", "value": 0.0349066,
            "sigma": 0.00872665}]})");
  const std::vector<FleetSeries> all = ReadFleet({tmp.Path("fleet")});
  const FleetSeries& steering = Find(all, "r1", "steering_offset");
  EXPECT_EQ(steering.unit, "deg");
  EXPECT_NEAR(steering.values.at(0), 2.0 * M_PI / 180.0, 1e-15);
  EXPECT_NEAR(steering.sigmas.at(0), 0.5 * M_PI / 180.0, 1e-15);
}

// FleetSeriesOf (validation/fleet_statistics.h) without files: a radius shrinking by exactly
// 0.1 mm a week, dates a week apart, has the slope 30/7 x 0.1 mm per 30 days to rounding and is a
// trend (no scatter about the line); one value 2 mm off among six that alternate +-1 um is the
// outlier (the robust sigma is 1.48 um), and the line leaves it out: with it the slope would be
// 2.4e-4 m per 30 days, without it below 1e-5. One robot name with two models is refused.
TEST(FleetStatistics, ExactDriftIsATrendAndOneJumpAnOutlier) {
  std::vector<FleetCalibration> all;
  const char* dates[] = {"2026-03-02", "2026-03-09", "2026-03-16",
                         "2026-03-23", "2026-03-30", "2026-04-06"};
  for (int week = 0; week < 6; ++week) {
    FleetCalibration c;
    c.file = std::string("cal") + std::to_string(week) + ".yaml";
    c.robot = "r1";
    c.model = "m";
    c.date = dates[week];
    c.values.push_back({"r_left", "m", 0.0420 - 0.0001 * week, 1.0});
    const double alternate = week % 2 == 0 ? 1e-6 : -1e-6;
    c.values.push_back({"r_right", "m", week == 3 ? 0.0440 : 0.0420 + alternate, 1.0});
    all.push_back(c);
  }
  std::reverse(all.begin(), all.end());  // sorted by date, whatever the order read
  const std::vector<FleetSeries> series = FleetSeriesOf(all);
  const FleetSeries& left = Find(series, "r1", "r_left");
  EXPECT_EQ(left.dates.front(), "2026-03-02");
  ASSERT_TRUE(left.has_slope);
  EXPECT_NEAR(left.slope_per_30_days, -0.0001 * 30.0 / 7.0, 1e-12);
  EXPECT_TRUE(left.trend);
  EXPECT_TRUE(left.outliers.empty());
  const FleetSeries& right = Find(series, "r1", "r_right");
  EXPECT_EQ(right.outliers, (std::vector<std::string>{"2026-03-23"}));
  EXPECT_FALSE(right.trend);
  EXPECT_LT(std::abs(right.slope_per_30_days), 1e-5);
  all[0].model = "other";
  EXPECT_THROW(FleetSeriesOf(all), io::InputError);
}

}  // namespace
}  // namespace fitcal
