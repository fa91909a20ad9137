#include "cli/asoc_commands.h"
#include "cli/cli_validators.h"

#include <cstdio>
#include <iostream>

#include "cli/dataset_command.h"
#include "io/output_guard.h"
#include "models/asoc/asoc_extras.h"
#include "models/asoc/asoc_tables.h"
#include "models/model_registry.h"
#include "sim/model_dataset.h"
#include "sim/model_scenarios.h"

namespace fitcal::tools {

namespace {

// The simulated prototype's encoders (Doebbler Sec. IV-B, V; models/asoc/asoc_extras.h): 20 Hz,
// wheels counted in 0.3 deg, ground truth noise-free at every encoder time from the origin, and
// the relative wheel-encoder noise of --wheel-slip-sigma on each 20 Hz increment.
sim::ScenarioNoise PrototypeEncoders(std::uint64_t seed, double wheel_slip_sigma, int excursions) {
  sim::ScenarioNoise noise;
  noise.repetitions = excursions;
  noise.seed = seed;
  noise.encoder_period_s = asoc::kPrototypeSamplePeriodS;
  noise.ground_truth_period_s = asoc::kPrototypeSamplePeriodS;
  noise.ticks_per_rev = asoc::kPrototypeWheelTicksPerRev;
  noise.wheel_rate_sigma_rad_s = 0.0;
  noise.wheel_relative_sigma = wheel_slip_sigma;
  noise.angle_sigma_rad = 0.0;
  noise.gt_position_sigma_m = 0.0;
  noise.gt_heading_sigma_rad = 0.0;
  noise.start_position_range_m = 0.0;
  return noise;
}

}  // namespace

int RunAsocSimulate(const AsocSimulateOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int {
    sim::ModelDatasetRequest request;
    request.out = options.out;
    request.model = "asoc";
    request.force = options.force;
    request.noise = PrototypeEncoders(options.seed, options.wheel_slip_sigma, options.excursions);
    const sim::WrittenModelDataset written = sim::WriteModelDataset(request);
    std::printf(
        "wrote %zu ASOC runs (6 calibration holds, 10 UMBmark, %d excursions) to %s; the "
        "true parameters are in true_robot.yaml\n",
        written.num_runs, options.excursions, options.out.c_str());
    return 0;
  });
}

int RunAsocGeometric(const FitCommandOptions& options) {
  FitCommandOptions closed_forms = options;
  closed_forms.closed_forms_only = true;
  return RunFitCommand(closed_forms);
}

int RunAsocTables(const AsocTablesOptions& options) {
  if (options.sets < 1) {
    std::cerr << "fitcal: --sets must be at least 1\n";
    return 2;
  }
  const RobotModelPtr model = ReadRobotModel(YAML::Load(kAsocExampleYaml), "asoc example robot");
  const auto& nominal = dynamic_cast<const AsocModel&>(*model);
  sim::SimulationOptions simulation =
      sim::MakeModelScenario(nominal, nominal.robot().nominal,
                             PrototypeEncoders(options.seed, options.wheel_slip_sigma, 0))
          .options;
  // UMBmark averages the runs' error vectors in the world frame: every run starts at the origin,
  // heading +x. The castors integrated at a tenth of the 20 Hz sample, as the paper's runs need.
  simulation.random_start_heading = false;
  simulation.substep_s = asoc::kPrototypeSamplePeriodS / 10.0;
  const asoc::SimulateFn simulate = [&](const std::vector<double>& truth,
                                        const std::vector<sim::TrajectorySpec>& specs,
                                        std::uint64_t seed) {
    sim::SimulationOptions o = simulation;
    o.seed = seed;
    std::vector<RunLog> logs;
    for (sim::ModelSimulatedRun& run : sim::SimulateRuns(nominal, truth, specs, o)) {
      logs.push_back(std::move(run.log));
    }
    return logs;
  };
  const asoc::DoebblerTables mean = asoc::SimulateDoebblerTables(
      nominal, options.sets, options.seed, simulate, options.threads);
  std::printf(
      "Doebbler et al. Tables I and II, %d random parameter sets (seed %llu, wheel slip "
      "sigma %g per 20 Hz sample)\n\n",
      options.sets, static_cast<unsigned long long>(options.seed), options.wheel_slip_sigma);
  std::printf("Table I: mean absolute parameter error\n\n");
  std::printf("| parameter | uncalibrated | calibrated | paper uncal. | paper cal. |\n");
  std::printf("|---|---|---|---|---|\n");
  const char* names[4] = {"r_c", "r_w", "d", "beta"};
  const char* paper[4][2] = {
      {"0.21%", "0.09%"}, {"2.07%", "0.04%"}, {"0.89%", "0.04%"}, {"7.98 deg", "0.01 deg"}};
  for (int k = 0; k < 4; ++k) {
    if (k < 3) {
      std::printf("| %s | %.3f%% | %.3f%% | %s | %s |\n", names[k], 100 * mean.param[0][k],
                  100 * mean.param[1][k], paper[k][0], paper[k][1]);
    } else {
      std::printf("| %s | %.3f deg | %.4f deg | %s | %s |\n", names[k], RadToDeg(mean.param[0][k]),
                  RadToDeg(mean.param[1][k]), paper[k][0], paper[k][1]);
    }
  }
  std::printf("\nTable II: UMBmark E_max (1.5 m square, 5 x CW and CCW, 6 m per circuit)\n\n");
  std::printf("| algorithm | uncalibrated | calibrated | ratio | paper uncal. | paper cal. |\n");
  std::printf("|---|---|---|---|---|---|\n");
  const char* alg[3] = {"IPEC-1", "CAST-1", "CAST-0"};
  const char* paper2[3][2] = {{"394.6 mm 6.89%", "71.7 mm 1.25%"},
                              {"394.1 mm 6.88%", "71.6 mm 1.25%"},
                              {"311.0 mm 5.43%", "39.0 mm 0.68%"}};
  for (int a = 0; a < 3; ++a) {
    std::printf("| %s | %.1f mm %.2f%% | %.2f mm %.3f%% | %.0fx | %s | %s |\n", alg[a],
                1000 * mean.emax[0][a], 100 * mean.emax[0][a] / 6.0, 1000 * mean.emax[1][a],
                100 * mean.emax[1][a] / 6.0, mean.emax[0][a] / mean.emax[1][a], paper2[a][0],
                paper2[a][1]);
  }
  std::printf(
      "\nratios: CAST-0 / two-castor uncalibrated %.3f (paper 0.79), calibrated %.3f "
      "(paper 0.54); IPEC-1 / CAST-1 uncalibrated %.4f (paper 1.0013)\n",
      mean.emax[0][2] / mean.emax[0][1], mean.emax[1][2] / mean.emax[1][1],
      mean.emax[0][0] / mean.emax[0][1]);
  return 0;
}

void AddAsocSimulateOptions(CLI::App& app, AsocSimulateOptions& simulate) {
  app.add_option("--out", simulate.out, "Output data set directory")->required();
  app.add_option("--seed", simulate.seed, "Random seed")->capture_default_str();
  app.add_option("--excursions", simulate.excursions, "Random excursion runs")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  app.add_option("--wheel-slip-sigma", simulate.wheel_slip_sigma,
                 "Relative wheel-encoder noise per 20 Hz sample")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  app.add_flag("--force", simulate.force, io::kForceDirectoryHelp);
}

void AddAsocGeometricOptions(CLI::App& app, FitCommandOptions& geometric) {
  AddDatasetOptions(app, geometric);
  geometric.out = "calibrated_asoc.yaml";
  app.add_option("--train-reps", geometric.train_reps,
                 "Repetitions the closed form is computed from (its hold_<i>_cw/ccw runs); the "
                 "others judge it against the nominal")
      ->capture_default_str()
      ->check(RepetitionListValidator());
  CLI::Option* out = app.add_option("--out", geometric.out, "Calibrated robot YAML (atomically)")
                         ->capture_default_str();
  // An --out given with --no-output would be dropped: one of them is a mistake (as fit).
  app.add_flag("--no-output", geometric.no_output, "Do not write the YAML")->excludes(out);
  app.add_flag("--force", geometric.force, io::kForceFileHelp);
}

void AddAsocTablesOptions(CLI::App& app, AsocTablesOptions& tables) {
  app.add_option("--sets", tables.sets, "Random parameter sets")->capture_default_str();
  app.add_option("--seed", tables.seed, "Random seed")->capture_default_str();
  app.add_option("--wheel-slip-sigma", tables.wheel_slip_sigma,
                 "Relative wheel-encoder noise per 20 Hz sample (non-systematic error)")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  app.add_option("--threads", tables.threads, "Worker threads (0 = all cores)")
      ->capture_default_str();
}

}  // namespace fitcal::tools
