#include "tools/simulate_command.h"

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/robot_yaml.h"
#include "odometry/parallel_for.h"

namespace fitcal::tools {

namespace fs = std::filesystem;

int RunSimulateCommand(const SimulateCommandOptions& options) {
  try {
    const Omni3Robot nominal = io::ReadOmni3Robot(options.robot);
    sim::Omni3SimulationOptions sim_options = options.sim;
    sim_options.commanded_robot = nominal.nominal;
    if (!options.truth.empty()) sim_options.true_robot = io::ReadOmni3Robot(options.truth).nominal;

    if (fs::exists(fs::path(options.out) / "dataset.yaml") && !options.force) {
      std::cerr << "fitcal: " << options.out
                << " already holds a data set; use --force to overwrite it\n";
      return 2;
    }
    const std::vector<sim::SimulatedRun> runs = sim::SimulateOmni3(sim_options);

    fs::create_directories(fs::path(options.out) / "runs");
    std::vector<io::DatasetEntry> entries(runs.size());
    ParallelFor(runs.size(), 0, [&](std::size_t i) {
      const RunLog& log = runs[i].log;
      io::DatasetEntry& e = entries[i];
      e.id = log.id;
      e.trajectory = log.trajectory;
      e.repetition = log.repetition;
      e.encoders = "runs/" + log.id + "_encoders.csv";
      e.ground_truth = "runs/" + log.id + "_ground_truth.csv";
      io::WriteFileAtomically((fs::path(options.out) / e.encoders).string(), io::EncoderCsv(log.encoders));
      io::WriteFileAtomically((fs::path(options.out) / e.ground_truth).string(),
                              io::GroundTruthCsv(log.ground_truth));
    });
    io::WriteFileAtomically((fs::path(options.out) / "robot.yaml").string(),
                            io::Omni3RobotYaml(nominal, nullptr));
    // dataset.yaml last: a data set is only complete once it exists.
    io::WriteFileAtomically((fs::path(options.out) / "dataset.yaml").string(),
                            io::DatasetYaml("robot.yaml", entries));
    std::printf("wrote %zu runs (%zu trajectories x %d repetitions, seed %llu) to %s\n", runs.size(),
                sim_options.trajectories.size(), sim_options.repetitions,
                static_cast<unsigned long long>(sim_options.seed), options.out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "fitcal: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace fitcal::tools
