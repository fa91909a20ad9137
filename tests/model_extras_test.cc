// A model's extras are found through the registry alone (models/model_extras.h): a toy model,
// registered here by one RegisterModel call with a controller writer, a simulation scenario and
// its compare columns, is exported, simulated and compared by the commands, which name no model;
// a data set simulated of it is fitted, reported, diagnosed and generalised by the commands too.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "io/dataset.h"
#include "io/ros2_parameter_yaml.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "tests/models/unicycle_test_model.h"
#include "tests/test_files.h"
#include "cli/compare_command.h"
#include "cli/diagnose_command.h"
#include "cli/export_ros2_control.h"
#include "cli/fit_command.h"
#include "cli/model_generalise_command.h"
#include "cli/report_command.h"
#include "sim/scenario_noise.h"
#include "cli/simulate_command.h"

namespace fitcal {
namespace {

using testing::TempDir;

constexpr char kToy[] = "test_unicycle";
constexpr char kController[] = "toy_unicycle_controller";
// The toy's default true robot: each free parameter this fraction of the way to a bound.
constexpr double kTruthFraction = 0.1;

// The toy controller writes the wheel radius it reads by name from the parameter table.
void ToyControllerParameters(const CalibratedRobot& c, const std::string&, ControllerExport* out) {
  const double radius_m = c.robot().nominal[c.Index("r")];
  out->parameters_yaml += "    wheel_joint: " + c.joints[0] +
                          "\n    wheel_radius: " + io::Ros2Double(radius_m) + "\n";
  out->model = c.model;
  out->parameters = c.robot().nominal;
}

// Two trajectories the unicycle can drive (it has no sideways motion): 1 m ahead, a turn.
std::vector<sim::TrajectorySpec> ToyScenario(const RobotModelInterface&, const std::vector<double>&,
                                              int repetitions) {
  std::vector<sim::TrajectorySpec> out;
  for (int rep = 1; rep <= repetitions; ++rep) {
    out.push_back({"ahead", rep, {{{0.2, 0.0, 0.0}, 5.0}}});
    out.push_back({"turn", rep, {{{0.0, 0.0, 0.5}, 4.0}}});
  }
  return out;
}

// compare shows the toy's radius in millimetres, under a header of its own.
ParameterDisplay ToyColumns(const Robot&) {
  ParameterDisplay d;
  d.markdown_header = "Toy radius";
  d.csv_names = {"toy_radius_mm"};
  d.csv_values = [](const std::vector<double>& p) { return std::vector<double>{1000.0 * p[0]}; };
  d.markdown = [](const std::vector<double>& p) { return std::to_string(1000.0 * p[0]) + " mm"; };
  return d;
}

// The toy model with its extras: one registration, as a model folder's one registry line.
void RegisterToyWithExtras() {
  ModelRegistration toy = *FindModel(kToy);
  toy.extras.controllers = {{kController, "jazzy rolling", &ToyControllerParameters}};
  toy.extras.scenario.trajectories = &ToyScenario;
  toy.extras.scenario.truth_fraction = kTruthFraction;
  toy.extras.display = &ToyColumns;
  RegisterModel(toy);
}

// The command's flags parsed as the CLI parses them, then the command run.
template <typename Options>
int RunCommand(void (*add)(CLI::App&, Options&), int (*run)(const Options&),
        std::vector<std::string> args) {
  CLI::App app;
  Options options;
  add(app, options);
  std::reverse(args.begin(), args.end());
  app.parse(args);
  return run(options);
}

TEST(ModelExtras, ExportFindsTheToysControllerWriterThroughTheRegistry) {
  RegisterToyWithExtras();
  const std::vector<std::string> controllers = Ros2Controllers();
  EXPECT_NE(std::find(controllers.begin(), controllers.end(), kController), controllers.end());

  TempDir dir;
  const std::string calibration = dir.Write(
      "toy.yaml", "model: test_unicycle\nname: toy\nradius_m: 0.0523\nturn_gain: 0.5\n"
                  "bounds: {radius_m: [0.04, 0.06], turn_gain: [0.4, 0.6]}\n");
  const std::string out = dir.Path("toy_controller.yaml");
  ASSERT_EQ(RunCommand(&tools::AddExportRos2ControlOptions, &tools::RunExportRos2ControlCommand,
                {"--calibration", calibration, "--controller", kController, "--out", out}),
            0);
  // The radius of the YAML above, written by the toy's own writer under the controller's node.
  const std::string text = testing::ReadFileBytes(out);
  EXPECT_TRUE(testing::Has(text, std::string(kController) + ":\n  ros__parameters:\n"
                                 "    wheel_joint: drive\n    wheel_radius: 0.0523\n"))
      << text;

  // A model that registers no writer for the controller is refused with the ones that do.
  const std::string diff_drive = dir.Write("diff_drive.yaml", kDiffDriveExampleYaml);
  EXPECT_EQ(RunCommand(&tools::AddExportRos2ControlOptions, &tools::RunExportRos2ControlCommand,
                {"--calibration", diff_drive, "--controller", kController}),
            2);
  try {
    ExportRos2Control(ReadRobotModelFile(diff_drive), diff_drive, kController, "", {});
    ADD_FAILURE() << "a diff_drive was exported as the toy's controller";
  } catch (const std::exception& e) {
    EXPECT_TRUE(testing::Has(e.what(), "(it takes model test_unicycle)")) << e.what();
  }
}

TEST(ModelExtras, SimulateFindsTheToysScenarioThroughTheRegistry) {
  RegisterToyWithExtras();
  EXPECT_TRUE(testing::Has(sim::ScenarioModelNames(), kToy)) << sim::ScenarioModelNames();

  TempDir dir;
  const std::string out = dir.Path("toy_data");
  ASSERT_EQ(RunCommand(&tools::AddSimulateOptions, &tools::RunSimulateCommand,
                {"--model", kToy, "--out", out, "--repetitions", "2"}),
            0);
  // The toy's trajectories, each repetition of each.
  std::multiset<std::string> runs;
  for (const io::DatasetIndexEntry& run : io::ReadDatasetIndex(out).runs) {
    runs.insert(run.trajectory + "/" + std::to_string(run.repetition));
  }
  EXPECT_EQ(runs, (std::multiset<std::string>{"ahead/1", "ahead/2", "turn/1", "turn/2"}));
  // The registered truth fraction moved the example robot (radius 0.05 in [0.04, 0.06], gain 0.5
  // in [0.4, 0.6]): the first free parameter toward its upper bound, the second toward its lower.
  const YAML::Node truth = YAML::LoadFile((std::filesystem::path(out) / "true_robot.yaml").string());
  EXPECT_NEAR(truth["radius_m"].as<double>(), 0.05 + kTruthFraction * (0.06 - 0.05), 1e-12);
  EXPECT_NEAR(truth["turn_gain"].as<double>(), 0.5 + kTruthFraction * (0.4 - 0.5), 1e-12);
}

TEST(ModelExtras, CompareShowsTheToysParametersAsTheToyRegisters) {
  RegisterToyWithExtras();
  TempDir dir;
  const std::string data = dir.Path("toy_data");
  ASSERT_EQ(RunCommand(&tools::AddSimulateOptions, &tools::RunSimulateCommand,
                       {"--model", kToy, "--out", data, "--repetitions", "2"}),
            0);
  const std::string out = dir.Path("cmp");
  ASSERT_EQ(RunCommand(&tools::AddCompareOptions, &tools::RunCompareCommand,
                       {"--logs", data, "--methods", "ceres", "--repetitions", "1", "--out", out,
                        "--quiet", "--threads", "1"}),
            0);
  const std::string csv = testing::ReadFileBytes(out + ".csv");
  ASSERT_TRUE(testing::Has(csv, "repetitions,toy_radius_mm,cf_calibration")) << csv;
  // The fitted row's radius in the toy's millimetres: inside the example's bounds, 0.04..0.06 m.
  const std::string row = csv.substr(csv.find("\nall,ceres,1,") + 1);
  const double radius_mm = testing::CsvNumbers(row.substr(row.find(",1,") + 3), 1)[0];
  EXPECT_GE(radius_mm, 40.0) << row;
  EXPECT_LE(radius_mm, 60.0) << row;
  EXPECT_TRUE(testing::Has(testing::ReadFileBytes(out + ".md"), "Toy radius"));
}

// The radius a robot YAML written by a command holds, read through the registry as every command
// reads it.
double RadiusOf(const std::string& robot_yaml) {
  const RobotModelPtr model = ReadRobotModelFile(robot_yaml);
  EXPECT_EQ(model->robot().model, kToy) << robot_yaml;
  return model->robot().nominal[0];
}

// Issue 41's measure: a toy model added through one registration runs fit, report, diagnose and
// generalise (export, simulate and compare: the tests above). Each command's effect is checked,
// so that one that names a model, or reads a data set through a model's own loader, breaks it.
TEST(ModelExtras, FitReportDiagnoseAndGeneraliseRunOnTheToysDataSet) {
  RegisterToyWithExtras();
  TempDir dir;
  const std::string data = dir.Path("toy_data");
  ASSERT_EQ(RunCommand(&tools::AddSimulateOptions, &tools::RunSimulateCommand,
                       {"--model", kToy, "--out", data, "--repetitions", "4"}),
            0);
  const double nominal_m = RadiusOf(data + "/robot.yaml");
  const double truth_m = RadiusOf(data + "/true_robot.yaml");

  // fit: writes the toy's YAML with a radius nearer the simulated truth than the nominal's.
  const std::string fitted = dir.Path("toy_fit.yaml");
  ASSERT_EQ(RunCommand(&tools::AddFitOptions, &tools::RunFitCommand,
                       {"--logs", data, "--train-reps", "1-2", "--out", fitted, "--threads", "1"}),
            0);
  EXPECT_LT(std::abs(RadiusOf(fitted) - truth_m), 0.5 * std::abs(nominal_m - truth_m));

  // report: the fitted YAML on the data set, its page and its metrics.json (parsed as YAML,
  // which JSON is a subset of).
  const std::string report = dir.Path("toy_report");
  ASSERT_EQ(RunCommand(&tools::AddReportOptions, &tools::RunReportCommand,
                       {"--logs", data, "--calibration", fitted, "--train-reps", "1-2", "--out",
                        report, "--threads", "1"}),
            0);
  EXPECT_TRUE(testing::Has(testing::ReadFileBytes(report + "/index.html"), "</html>"));
  EXPECT_TRUE(YAML::LoadFile(report + "/metrics.json").IsMap());

  // diagnose: its calibrated YAML is the toy's, read back through the registry.
  const std::string diagnosed = dir.Path("toy_diagnose");
  ASSERT_EQ(RunCommand(&tools::AddDiagnoseOptions, &tools::RunDiagnoseCommand,
                       {"--logs", data, "--out", diagnosed, "--threads", "1"}),
            0);
  EXPECT_LT(std::abs(RadiusOf(diagnosed + "/calibrated.yaml") - truth_m),
            0.5 * std::abs(nominal_m - truth_m));
  EXPECT_TRUE(YAML::LoadFile(diagnosed + "/metrics.json").IsMap());

  // generalise: writes nothing; its table scores the fit trained on one path type on the other.
  ::testing::internal::CaptureStdout();
  const int generalised = RunCommand(&tools::AddGeneraliseOptions, &tools::RunGeneraliseCommand,
                                     {"--logs", data, "--threads", "1"});
  const std::string table = ::testing::internal::GetCapturedStdout();
  ASSERT_EQ(generalised, 0) << table;
  EXPECT_TRUE(testing::Has(table, "| ahead -> turn | fit |")) << table;
  EXPECT_TRUE(testing::Has(table, "| turn -> ahead | fit |")) << table;
}

}  // namespace
}  // namespace fitcal
