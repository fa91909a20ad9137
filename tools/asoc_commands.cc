#include "tools/asoc_commands.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>

#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/staged_directory.h"
#include "io/yaml_text.h"
#include "models/asoc/asoc_files.h"
#include "models/asoc/asoc_geometric.h"
#include "tools/dataset_command.h"
#include "tools/output_guard.h"
#include "tools/sim/asoc_scenarios.h"

namespace fitcal::tools {

namespace fs = std::filesystem;

namespace {

void PrintCastors(const io::AsocRobot& robot,
                  const std::array<asoc::CastorParameters, asoc::kNumCastors>& castors,
                  const char* label) {
  std::printf("\n  %-8s %10s %10s %10s %10s %10s %12s   (%s)\n", "castor", "r_c [m]", "r_w1 [m]",
              "r_w2 [m]", "d_1 [m]", "d_2 [m]", "beta [deg]", label);
  for (int i = 0; i < asoc::kNumCastors; ++i) {
    const asoc::CastorParameters& c = castors[i];
    std::printf("  %-8s %10.6f %10.6f %10.6f %10.6f %10.6f %12.4f\n", robot.castor_names[i].c_str(),
                c.offset_m, c.wheel_radius_m[0], c.wheel_radius_m[1], c.wheel_offset_m[0],
                c.wheel_offset_m[1], RadToDeg(c.encoder_bias_rad));
  }
}

// The calibration record of the written YAML: how it was made, and the 1-sigma uncertainty of
// each castor's parameters from the spread of its estimates over hold runs
// (asoc::GeometricResult::sigma). Emitted by yaml-cpp so that any path is quoted correctly.
std::string AsocCalibrationRecord(const std::string& method, const std::string& dataset,
                                  const io::AsocRobot& robot, const asoc::GeometricResult& result) {
  YAML::Emitter out;
  out.SetMapFormat(YAML::Flow);
  out << YAML::BeginMap << YAML::Key << "method" << YAML::Value << method << YAML::Key << "dataset"
      << YAML::Value << io::YamlText(dataset) << YAML::Key << "tool_version" << YAML::Value
      << kVersion << YAML::Key << "sigma_dof" << YAML::Value << result.sigma_dof;
  out << YAML::Key << "sigma" << YAML::Value << YAML::BeginMap;
  for (int i = 0; i < asoc::kNumCastors; ++i) {
    const asoc::CastorParameters& h = result.sigma[i];
    out << YAML::Key << io::YamlText(robot.castor_names[i]) << YAML::Value << YAML::BeginMap
        << YAML::Key << "offset_m" << YAML::Value << h.offset_m << YAML::Key << "wheel_radius_m"
        << YAML::Value << YAML::BeginSeq << h.wheel_radius_m[0] << h.wheel_radius_m[1]
        << YAML::EndSeq << YAML::Key << "wheel_offset_m" << YAML::Value << YAML::BeginSeq
        << h.wheel_offset_m[0] << h.wheel_offset_m[1] << YAML::EndSeq << YAML::Key
        << "encoder_bias_deg" << YAML::Value << RadToDeg(h.encoder_bias_rad) << YAML::EndMap;
  }
  out << YAML::EndMap << YAML::EndMap;
  return out.c_str();
}

// Writes `robot` with the calibrated castors and the record above to `out` (atomically), and says
// so. Refuses (std::runtime_error) when no castor has two independent estimates (hold runs of two
// different held castors): nothing would say how well it is known, and a written calibration
// always carries its uncertainty.
void WriteAsocCalibration(const std::string& out, const io::AsocRobot& robot,
                          const asoc::GeometricResult& result, const std::string& method,
                          const std::string& dataset) {
  if (result.sigma_dof < 1) {
    throw std::runtime_error(dataset +
                             ": no castor has two independent closed-form estimates: no "
                             "uncertainty; nothing written (record a CW and a CCW hold run of "
                             "each castor)");
  }
  io::AsocRobot calibrated = robot;
  calibrated.nominal = result.estimate;
  io::WriteFileAtomically(
      out, io::AsocRobotYaml(calibrated, AsocCalibrationRecord(method, dataset, robot, result)));
  std::printf("wrote %s\n", out.c_str());
}

}  // namespace

int RunAsocSimulate(const AsocSimulateOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int {
    if (const std::string refusal =
            DirectoryOutputRefusal(options.out, kDatasetKind, options.force, {});
        !refusal.empty()) {
      std::cerr << "fitcal: " << refusal << "\n";
      return 2;
    }
    // Written whole or not at all: staged beside --out, renamed over it once complete.
    io::StagedDirectory staged(options.out);
    const fs::path out(staged.path());
    fs::create_directories(out / "runs");
    const sim::AsocSimulatedDataset simulated =
        sim::SimulateAsocDataset(options.seed, options.wheel_slip_sigma, options.excursions);
    const std::vector<asoc::RunLog>& runs = simulated.runs;
    std::vector<io::DatasetEntry> entries;
    for (const asoc::RunLog& run : runs) {
      const std::string enc = "runs/" + run.id + "_encoders.csv";
      const std::string gt = "runs/" + run.id + "_ground_truth.csv";
      io::WriteFileAtomically((out / enc).string(), io::AsocEncoderCsv(run.encoders));
      io::WriteFileAtomically((out / gt).string(), io::GroundTruthCsv(run.ground_truth));
      entries.push_back({run.id, run.trajectory, run.repetition, enc, gt});
    }
    io::WriteFileAtomically((out / "robot.yaml").string(), io::AsocRobotYaml(simulated.nominal));
    io::WriteFileAtomically((out / "truth.yaml").string(), io::AsocRobotYaml(simulated.truth));
    io::WriteFileAtomically((out / "dataset.yaml").string(),
                            io::DatasetYaml("robot.yaml", entries));
    CommitDirectoryOutput(staged, options.out, kDatasetKind, options.force, {});
    std::printf(
        "wrote %zu ASOC runs (6 calibration holds, 10 UMBmark, %d excursions) to %s; the "
        "true parameters are in truth.yaml\n",
        runs.size(), options.excursions, options.out.c_str());
    return 0;
  });
}

int RunAsocGeometric(const AsocGeometricOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int {
    io::DatasetOptions dataset_options;
    dataset_options.allow_paths_outside = options.allow_outside_paths;
    if (!options.no_output) {  // before the work: never over one of the data set's files
      const std::string refusal = OutputFileRefusal(
          options.out, DatasetInputs(io::ReadDatasetIndex(options.logs, dataset_options)));
      if (!refusal.empty()) {
        std::cerr << "fitcal: " << refusal << "\n";
        return 2;
      }
    }
    const io::AsocDataset dataset = io::LoadAsocDataset(options.logs, dataset_options);
    const io::AsocRobot robot = io::ReadAsocRobot(dataset.robot_path);
    asoc::GeometricOptions geometric;
    geometric.pivot_resolution_rad = robot.pivot_resolution_rad;
    const asoc::GeometricResult result =
        asoc::CalibrateGeometric(dataset.runs, robot.nominal, geometric);
    std::printf("fitcal %s  asoc robot '%s'  closed-form calibration (Doebbler Eq. 1-9)  %s\n",
                kVersion, robot.name.c_str(), options.logs.c_str());
    PrintCastors(robot, robot.nominal.castors, "nominal");
    PrintCastors(robot, result.estimate.castors, "calibrated");
    std::printf(
        "\n  %-8s %10s %10s %10s %10s %10s %12s   (+-1 sigma: spread over hold runs and "
        "the pivot step)\n",
        "castor", "r_c [m]", "r_w1 [m]", "r_w2 [m]", "d_1 [m]", "d_2 [m]", "beta [deg]");
    for (int i = 0; i < asoc::kNumCastors; ++i) {
      const asoc::CastorParameters& s = result.sigma[i];
      std::printf("  %-8s %10.2g %10.2g %10.2g %10.2g %10.2g %12.2g\n",
                  robot.castor_names[i].c_str(), s.offset_m, s.wheel_radius_m[0],
                  s.wheel_radius_m[1], s.wheel_offset_m[0], s.wheel_offset_m[1],
                  RadToDeg(s.encoder_bias_rad));
    }
    std::printf(
        "\n  sigmas from %d degrees of freedom; half-difference of the estimates per "
        "castor (repeatability):\n",
        result.sigma_dof);
    for (int i = 0; i < asoc::kNumCastors; ++i) {
      const asoc::CastorParameters& h = result.half_spread[i];
      std::printf(
          "  %-8s r_c %.2g m, r_w %.2g/%.2g m, d %.2g/%.2g m, beta %.3g deg (%d estimates)\n",
          robot.castor_names[i].c_str(), h.offset_m, h.wheel_radius_m[0], h.wheel_radius_m[1],
          h.wheel_offset_m[0], h.wheel_offset_m[1], RadToDeg(h.encoder_bias_rad),
          result.num_estimates[i]);
    }
    if (result.usable) std::printf("  %s\n", result.message.c_str());
    if (!result.usable) {
      // Too few or inconsistent hold runs: the data's fault, not a fit that did not converge.
      std::cerr << "fitcal: closed form not usable: " << result.message << " nothing written\n";
      return 1;
    }
    if (!options.no_output) {
      if (const std::string refusal = OverwriteRefusal(options.out, robot.name);
          !refusal.empty() && !options.force) {
        std::cerr << "fitcal: " << refusal << "\n";
        return 2;
      }
      WriteAsocCalibration(options.out, robot, result, "closed-form Doebbler Eq. 1-9",
                           options.logs);
    }
    return 0;
  });
}

int RunAsocTables(const AsocTablesOptions& options) {
  if (options.sets < 1) {
    std::cerr << "fitcal: --sets must be at least 1\n";
    return 2;
  }
  const sim::DoebblerTables mean = sim::SimulateDoebblerTables(
      options.sets, options.seed, options.wheel_slip_sigma, options.threads);
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
      ->check(CLI::NonNegativeNumber);
  app.add_option("--wheel-slip-sigma", simulate.wheel_slip_sigma,
                 "Relative wheel-encoder noise per 20 Hz sample")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--force", simulate.force, kForceDirectoryHelp);
}

void AddAsocGeometricOptions(CLI::App& app, AsocGeometricOptions& geometric) {
  app.add_option("--logs", geometric.logs, "Data set with hold_<i>_cw/ccw runs")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--out", geometric.out, "Calibrated robot YAML (atomically)")
      ->capture_default_str();
  app.add_flag("--no-output", geometric.no_output, "Do not write the YAML");
  app.add_flag("--force", geometric.force, kForceFileHelp);
  app.add_flag("--allow-outside-paths", geometric.allow_outside_paths,
               "Allow dataset.yaml paths outside the data set directory");
}

void AddAsocTablesOptions(CLI::App& app, AsocTablesOptions& tables) {
  app.add_option("--sets", tables.sets, "Random parameter sets")->capture_default_str();
  app.add_option("--seed", tables.seed, "Random seed")->capture_default_str();
  app.add_option("--wheel-slip-sigma", tables.wheel_slip_sigma,
                 "Relative wheel-encoder noise per 20 Hz sample (non-systematic error)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--threads", tables.threads, "Worker threads (0 = all cores)")
      ->capture_default_str();
}

}  // namespace fitcal::tools
