#include "cli/model_simulate_command.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/staged_directory.h"
#include "models/model_registry.h"
#include "io/command_failure.h"
#include "cli/dataset_command.h"
#include "io/output_guard.h"
#include "sim/model_scenarios.h"
#include "sim/model_simulator.h"

namespace fitcal::tools {

namespace fs = std::filesystem;

namespace {

// The nominal robot: --robot, or the registry's example robot of the model.
RobotModelPtr NominalModel(const ModelSimulateOptions& options) {
  if (!options.robot.empty()) return ReadRobotModelFile(options.robot);
  const ModelRegistration* registration = FindModel(options.model);
  if (registration == nullptr) {
    throw std::invalid_argument("unknown --model '" + options.model +
                                "' (known: " + RegisteredModelNames() + ")");
  }
  return ReadRobotModel(YAML::Load(registration->example_yaml), options.model + " example robot");
}

// The true parameters: --truth (a robot YAML of the same model and channels), or the default.
std::vector<double> TrueParameters(const ModelSimulateOptions& options,
                                   const RobotModelInterface& nominal) {
  const Robot& robot = nominal.robot();
  if (options.truth.empty()) return sim::DefaultTrueParameters(robot);
  const RobotModelPtr truth = ReadRobotModelFile(options.truth);
  const Robot& t = truth->robot();
  if (t.model != robot.model || t.NumChannels() != robot.NumChannels() ||
      t.NumParameters() != robot.NumParameters()) {
    throw std::invalid_argument(options.truth + ": the true robot must be a " + robot.model +
                                " robot with the nominal robot's channels and parameters");
  }
  return t.nominal;
}

void PrintTruth(const Robot& robot, const std::vector<double>& truth) {
  std::printf("  %-22s %12s %12s\n", "parameter", "nominal", "true");
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const double s = robot.parameters[k].DisplayScale();
    std::printf("  %-22s %12.6f %12.6f%s\n", robot.LabelOf(k).c_str(), robot.nominal[k] * s,
                truth[k] * s, robot.IsHeld(k) ? "  held (gauge)" : "");
  }
}

}  // namespace

int RunModelSimulateCommand(const ModelSimulateOptions& options) {
  return RunReportingErrors("fitcal simulate", [&]() -> int {
    if (!options.flower_only_flags.empty()) {
      throw UsageError(options.flower_only_flags.front() +
                       " belongs to the flower simulation (simulate without --model), not to "
                       "--model " + options.model + " (docs/simulate.md)");
    }
    if (const std::string refusal =
            io::DirectoryOutputRefusal(options.out, io::kDatasetKind, options.force, {});
        !refusal.empty()) {
      throw UsageError(refusal);
    }
    const RobotModelPtr model = NominalModel(options);
    const Robot& robot = model->robot();
    if (robot.model != options.model) {
      throw UsageError(options.robot + " is a " + robot.model + " robot, not " + options.model);
    }
    const std::vector<double> truth = TrueParameters(options, *model);
    const sim::ScenarioNoise& noise = options.noise;
    const sim::ModelScenario scenario = sim::MakeModelScenario(*model, truth, noise);
    const std::vector<sim::ModelSimulatedRun> runs =
        sim::SimulateRuns(*model, truth, scenario.trajectories, scenario.options);
    {
      io::StagedDirectory staged(options.out);
      sim::WriteSimulatedDataset(staged.path(), model->RobotYaml(robot.nominal, ""), runs);
      io::WriteFileAtomically((fs::path(staged.path()) / "true_robot.yaml").string(),
                              model->RobotYaml(truth, ""));
      io::CommitDirectoryOutput(staged, options.out, io::kDatasetKind, options.force, {});
    }
    std::printf("wrote %zu runs of the %s robot '%s' (%d repetitions, seed %llu) to %s\n",
                runs.size(), robot.model.c_str(), robot.name.c_str(), noise.repetitions,
                static_cast<unsigned long long>(noise.seed), options.out.c_str());
    PrintTruth(robot, truth);
    return 0;
  });
}

}  // namespace fitcal::tools
