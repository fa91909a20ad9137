#include "sim/model_dataset.h"

#include <cmath>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <vector>

#include "io/atomic_file.h"
#include "io/command_failure.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/output_guard.h"
#include "io/staged_directory.h"
#include "models/model_registry.h"
#include "sim/model_scenarios.h"
#include "sim/model_simulator.h"

namespace fitcal::sim {

namespace fs = std::filesystem;

namespace {

// The nominal robot: --robot, or the registry's example robot of the model.
RobotModelPtr NominalModel(const ModelDatasetRequest& request) {
  if (!request.robot.empty()) return ReadRobotModelFile(request.robot);
  const ModelRegistration* registration = FindModel(request.model);
  if (registration == nullptr) {
    throw std::invalid_argument("unknown --model '" + request.model +
                                "' (known: " + RegisteredModelNames() + ")");
  }
  return ReadRobotModel(YAML::Load(registration->example_yaml), request.model + " example robot");
}

// Whether two models of one kind step alike at parameters p: each channel alone and all together
// (their fixed geometry, what is not a parameter, is the same).
bool StepAlike(const RobotModelInterface& a, const RobotModelInterface& b,
               const std::vector<double>& p) {
  const auto step_a = a.PrepareKinematics(p.data());
  const auto step_b = b.PrepareKinematics(p.data());
  const int n = a.robot().NumChannels();
  for (int k = 0; k <= n; ++k) {
    std::vector<double> values(n, 0.0);
    for (int i = 0; i < n; ++i) values[i] = k == n ? 0.3 + 0.1 * i : i == k ? 1.0 : 0.0;
    double da[3], db[3];
    step_a->Step(values.data(), 0.01, &da[0], &da[1], &da[2]);
    step_b->Step(values.data(), 0.01, &db[0], &db[1], &db[2]);
    for (int c = 0; c < 3; ++c) {
      if (!(std::abs(da[c] - db[c]) <= 1e-12 + 1e-9 * std::abs(da[c]))) return false;
    }
  }
  return true;
}

// The true parameters: --truth (a robot YAML of the same model and channels), or the default.
std::vector<double> TrueParameters(const ModelDatasetRequest& request,
                                   const RobotModelInterface& nominal) {
  const Robot& robot = nominal.robot();
  if (request.truth.empty()) return DefaultTrueParameters(robot, request.noise.seed);
  const RobotModelPtr truth = ReadRobotModelFile(request.truth);
  const Robot& t = truth->robot();
  if (t.model != robot.model || t.NumChannels() != robot.NumChannels() ||
      t.NumParameters() != robot.NumParameters()) {
    throw std::invalid_argument(request.truth + ": the true robot must be a " + robot.model +
                                " robot with the nominal robot's channels and parameters");
  }
  if (!StepAlike(nominal, *truth, t.nominal)) {
    throw std::invalid_argument(
        request.truth + ": the true robot differs from the nominal robot in more than its "
        "parameters (geometry the model does not fit, such as an omni wheel's drive or roller "
        "angle); the simulation would drive the nominal's: make it the same in both files");
  }
  return t.nominal;
}

// Noise beyond the loader's physical limits (a ground truth beyond any map, a wheel rate no wheel
// turns: sigmas of 1e300 were written, then refused by `fit`) is refused here, nothing written.
void RefuseWhatFitRefuses(const std::string& staged_dir, const std::string& out,
                          const Robot& robot) {
  try {
    io::ReadBackStagedDataset(staged_dir, out, robot);
  } catch (const io::InputError& e) {
    throw UsageError(std::string("the noise asked for makes a data set fit would refuse: ") +
                     e.what());
  }
}

// `out` refused by the overwrite rule (io/output_guard.h; UsageError) before anything is
// simulated; `write` fills a staged sibling directory, then renamed over `out`.
void WriteDatasetDirectory(const std::string& out, bool force,
                           const std::function<void(const std::string& directory)>& write) {
  if (const std::string refusal = io::DirectoryOutputRefusal(out, io::kDatasetKind, force, {});
      !refusal.empty()) {
    throw UsageError(refusal);
  }
  io::StagedDirectory staged(out);
  write(staged.path());
  io::CommitDirectoryOutput(staged, out, io::kDatasetKind, force, {});
}

}  // namespace

WrittenModelDataset WriteModelDataset(const ModelDatasetRequest& request) {
  WrittenModelDataset written;
  WriteDatasetDirectory(request.out, request.force, [&](const std::string& directory) {
    written.model = NominalModel(request);
    const RobotModelInterface& model = *written.model;
    const Robot& robot = model.robot();
    if (!request.model.empty() && robot.model != request.model) {
      throw UsageError(request.robot + " is a " + robot.model + " robot, not " + request.model);
    }
    written.truth = TrueParameters(request, model);
    const ModelScenario scenario = MakeModelScenario(model, written.truth, request.noise);
    const std::vector<ModelSimulatedRun> runs =
        SimulateRuns(model, written.truth, scenario.trajectories, scenario.options);
    WriteSimulatedDataset(directory, model.RobotYaml(robot.nominal, ""), runs, scenario.digits);
    RefuseWhatFitRefuses(directory, request.out, robot);
    io::WriteFileAtomically((fs::path(directory) / "true_robot.yaml").string(),
                            model.RobotYaml(written.truth, ""));
    written.num_runs = runs.size();
    written.repetitions = scenario.repetitions;
    written.repetition_unit = scenario.repetition_unit;
  });
  return written;
}

}  // namespace fitcal::sim
