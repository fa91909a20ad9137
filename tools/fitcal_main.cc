// fitcal: offline calibration of wheeled odometry. Subcommands are registered in a table below;
// `fitcal --logs <dir> --method ceres` without a subcommand runs `fit`.

#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>

#include "fitcal/version.h"
#include "tools/fit_command.h"
#include "tools/simulate_command.h"

namespace {

void AddFitOptions(CLI::App& app, fitcal::tools::FitCommandOptions& o) {
  app.add_option("--logs", o.logs, "Data set directory (holds dataset.yaml)")->check(CLI::ExistingDirectory);
  app.add_option("--method", o.method, "Solver: ceres")->capture_default_str();
  app.add_option("--train-reps", o.train_reps,
                 "Repetitions used for fitting, e.g. 1-5 or 1,3,5; the others validate")
      ->capture_default_str();
  app.add_option("--out", o.out, "Calibrated robot YAML to write (atomically)")->capture_default_str();
  app.add_flag("--no-output", o.no_output, "Do not write the calibrated YAML");
  app.add_flag("--allow-outside-paths", o.allow_outside_paths,
               "Allow dataset.yaml paths that are absolute or leave the data set directory");
  app.add_option("--threads", o.threads, "Worker threads (0 = all cores)")->capture_default_str();
  app.add_option("--position-sigma-m", o.position_sigma_m,
                 "Weight of the position residual as a standard deviation (m); with the default "
                 "1 m and 57.3 deg the objective weighs metres and radians as Eq. 14")
      ->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--heading-sigma-deg", o.heading_sigma_deg,
                 "Weight of the heading residual as a standard deviation (deg)")
      ->capture_default_str()->check(CLI::PositiveNumber);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fitcal " + std::string(fitcal::kVersion) +
               ": calibrate the kinematic parameters of a wheeled robot's odometry from encoder "
               "logs and ground truth"};
  app.set_version_flag("--version", std::string(fitcal::kVersion));
  app.require_subcommand(0, 1);

  fitcal::tools::FitCommandOptions fit;
  AddFitOptions(app, fit);
  CLI::App* fit_cmd = app.add_subcommand("fit", "Fit, validate on held-out repetitions, write the calibrated YAML (default)");
  fit_cmd->fallthrough();

  fitcal::tools::SimulateCommandOptions simulate;
  CLI::App* sim_cmd = app.add_subcommand("simulate", "Write a simulated flower data set (docs/simulator.md)");
  sim_cmd->add_option("--out", simulate.out, "Output data set directory")->required();
  sim_cmd->add_option("--robot", simulate.robot, "Nominal robot YAML (commands and fit start)")
      ->capture_default_str()->check(CLI::ExistingFile);
  sim_cmd->add_option("--truth", simulate.truth, "Robot YAML of the true robot (default: Palacin Table 5)")
      ->check(CLI::ExistingFile);
  sim_cmd->add_option("--repetitions", simulate.sim.repetitions, "Repetitions of each trajectory")
      ->capture_default_str()->check(CLI::PositiveNumber);
  sim_cmd->add_option("--seed", simulate.sim.seed, "Random seed")->capture_default_str();
  sim_cmd->add_option("--encoder-counts-per-rev", simulate.sim.encoder_counts_per_rev,
                      "Encoder resolution")->capture_default_str();
  sim_cmd->add_option("--gt-position-sigma-m", simulate.sim.gt_position_sigma_m,
                      "Ground-truth position noise (m)")->capture_default_str();
  double gt_heading_sigma_deg = simulate.sim.gt_heading_sigma_rad * 180.0 / M_PI;
  sim_cmd->add_option("--gt-heading-sigma-deg", gt_heading_sigma_deg, "Ground-truth heading noise (deg)")
      ->capture_default_str();
  sim_cmd->add_option("--slip-sigma", simulate.sim.slip_sigma, "Relative wheel slip noise")
      ->capture_default_str();
  sim_cmd->add_flag("--force", simulate.force, "Overwrite an existing data set");

  CLI11_PARSE(app, argc, argv);

  if (app.got_subcommand(sim_cmd)) {
    simulate.sim.gt_heading_sigma_rad = gt_heading_sigma_deg * M_PI / 180.0;
    return fitcal::tools::RunSimulateCommand(simulate);
  }
  if (fit.logs.empty()) {
    std::cerr << "fitcal: --logs <data set directory> is required (see fitcal --help)\n";
    return 2;
  }
  return fitcal::tools::RunFitCommand(fit);
}
