#include "tools/simulate_command.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/robot_yaml.h"
#include "io/staged_directory.h"
#include "odometry/parallel_for.h"
#include "tools/model_simulate_command.h"
#include "tools/output_guard.h"

namespace fitcal::tools {

namespace fs = std::filesystem;

namespace {

// "name=v1[,v2]" -> an effect of the registry with its values, checked against its bounds.
effects::EffectValue ParseInjectedEffect(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos)
    throw std::invalid_argument("--inject '" + text + "': expected name=value[,value]");
  effects::EffectValue e;
  e.id = effects::EffectIdFromName(text.substr(0, eq));
  const effects::EffectInfo& info = effects::Info(e.id);
  // The flower robot has three wheel channels: an effect on a steering angle or on a wheel pair
  // would be written nowhere (a data set that silently lacks the effect asked for).
  if (effects::NeedsAngleChannel(e.id) || effects::NeedsWheelPair(e.id)) {
    throw std::invalid_argument(
        "--inject '" + text + "': " + info.name +
        " cannot act on the omni3 flower robot (it needs " +
        (effects::NeedsWheelPair(e.id) ? "a pair of wheels" : "a steering angle") + ")");
  }
  std::string rest = text.substr(eq + 1);
  for (int k = 0; k < info.num_parameters; ++k) {
    const std::size_t comma = rest.find(',');
    const std::string item = rest.substr(0, comma);
    std::size_t used = 0;
    try {
      e.value[k] = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() ||
        !(e.value[k] >= info.lower[k] && e.value[k] <= info.upper[k])) {
      throw std::invalid_argument("--inject '" + text + "': " + info.parameter_names[k] +
                                  " must be a number in [" + std::to_string(info.lower[k]) + ", " +
                                  std::to_string(info.upper[k]) + "]");
    }
    rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
    if (k + 1 < info.num_parameters && comma == std::string::npos) {
      throw std::invalid_argument("--inject '" + text + "': " + info.name + " takes " +
                                  std::to_string(info.num_parameters) + " values");
    }
  }
  if (!rest.empty()) throw std::invalid_argument("--inject '" + text + "': too many values");
  return e;
}

// --model: the generic simulator with the flags that apply to it.
int RunModelSimulate(const SimulateCommandOptions& options) {
  ModelSimulateOptions o;
  o.out = options.out;
  o.model = options.model;
  o.robot = options.robot_given ? options.robot : "";
  o.truth = options.truth;
  o.force = options.force;
  o.noise.repetitions = options.sim.repetitions;
  o.noise.seed = options.sim.seed;
  o.noise.ticks_per_rev = options.sim.encoder_counts_per_rev;
  o.noise.wheel_rate_sigma_rad_s = options.wheel_rate_sigma_rad_s;
  o.noise.angle_sigma_rad = options.angle_sigma_deg * M_PI / 180.0;
  o.noise.gt_position_sigma_m = options.sim.gt_position_sigma_m;
  o.noise.gt_heading_sigma_rad = options.sim.gt_heading_sigma_rad;
  o.omni3_only_flags = options.omni3_only_flags;
  return RunModelSimulateCommand(o);
}

}  // namespace

void AddSimulateOptions(CLI::App& app, SimulateCommandOptions& o) {
  app.add_option("--out", o.out, "Output data set directory")->required();
  app.add_option(
      "--model", o.model,
      "Robot model (" + sim::ScenarioModelNames() + "; default: the omni3 flower simulator)");
  app.add_option("--robot", o.robot, "Nominal robot YAML (commands and fit start)")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  app.add_option("--truth", o.truth, "Robot YAML of the true robot (default: Palacin Table 5)")
      ->check(CLI::ExistingFile);
  app.add_option("--repetitions", o.sim.repetitions, "Repetitions of each trajectory")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--seed", o.sim.seed, "Random seed")->capture_default_str();
  app.add_option("--encoder-counts-per-rev", o.sim.encoder_counts_per_rev, "Encoder resolution")
      ->capture_default_str();
  app.add_option("--gt-position-sigma-m", o.sim.gt_position_sigma_m,
                 "Ground-truth position noise (m)")
      ->capture_default_str();
  app.add_option("--gt-heading-sigma-deg", o.gt_heading_sigma_deg,
                 "Ground-truth heading noise (deg)")
      ->capture_default_str();
  app.add_option("--slip-sigma", o.sim.slip_sigma, "Relative wheel slip noise")
      ->capture_default_str();
  app.add_option("--wheel-rate-sigma-rad-s", o.wheel_rate_sigma_rad_s,
                 "--model: white noise on each interval's mean wheel rate (rad/s)")
      ->capture_default_str();
  app.add_option("--angle-sigma-deg", o.angle_sigma_deg,
                 "--model: noise of an angle channel's readings, e.g. steering (deg)")
      ->capture_default_str();
  app.add_flag("--force", o.force, "Overwrite an existing data set");
  app.add_option("--inject", o.inject,
                 "Inject a library effect, name=value[,value] (odometry/effects.h); repeatable; "
                 "the data set does not name it");
  app.callback([&app, &o] {
    o.sim.gt_heading_sigma_rad = o.gt_heading_sigma_deg * M_PI / 180.0;
    o.robot_given = app.count("--robot") > 0;
    for (const char* flag : {"--slip-sigma", "--inject"}) {
      if (app.count(flag) > 0) o.omni3_only_flags.push_back(flag);
    }
  });
}

int RunSimulateCommand(const SimulateCommandOptions& options) {
  if (!options.model.empty() && options.model != "omni3") return RunModelSimulate(options);
  try {
    const Omni3Robot nominal = io::ReadOmni3Robot(options.robot);
    sim::Omni3SimulationOptions sim_options = options.sim;
    sim_options.commanded_robot = nominal.nominal;
    if (!options.truth.empty()) sim_options.true_robot = io::ReadOmni3Robot(options.truth).nominal;
    for (const std::string& text : options.inject) {
      sim_options.injected_effects.push_back(ParseInjectedEffect(text));
    }

    if (const std::string refusal =
            DirectoryOutputRefusal(options.out, kDatasetKind, options.force, {});
        !refusal.empty()) {
      std::cerr << "fitcal: " << refusal << "\n";
      return 2;
    }
    const std::vector<sim::SimulatedRun> runs = sim::SimulateOmni3(sim_options);

    // Written whole or not at all: staged beside --out, renamed over it once complete.
    io::StagedDirectory staged(options.out);
    const fs::path out(staged.path());
    fs::create_directories(out / "runs");
    std::vector<io::DatasetEntry> entries(runs.size());
    ParallelFor(runs.size(), 0, [&](std::size_t i) {
      const RunLog& log = runs[i].log;
      io::DatasetEntry& e = entries[i];
      e.id = log.id;
      e.trajectory = log.trajectory;
      e.repetition = log.repetition;
      e.encoders = "runs/" + log.id + "_encoders.csv";
      e.ground_truth = "runs/" + log.id + "_ground_truth.csv";
      io::WriteFileAtomically((out / e.encoders).string(), io::EncoderCsv(log.encoders));
      io::WriteFileAtomically((out / e.ground_truth).string(),
                              io::GroundTruthCsv(log.ground_truth));
    });
    io::WriteFileAtomically((out / "robot.yaml").string(), io::Omni3RobotYaml(nominal, nullptr));
    io::WriteFileAtomically((out / "dataset.yaml").string(),
                            io::DatasetYaml("robot.yaml", entries));
    CommitDirectoryOutput(staged, options.out, kDatasetKind, options.force, {});
    std::printf("wrote %zu runs (%zu trajectories x %d repetitions, seed %llu) to %s\n",
                runs.size(), sim_options.trajectories.size(), sim_options.repetitions,
                static_cast<unsigned long long>(sim_options.seed), options.out.c_str());
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "fitcal: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace fitcal::tools
