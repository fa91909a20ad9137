#pragma once
// ASOC subcommands (Doebbler et al.): `asoc-simulate` writes an ASOC data set, `asoc-geometric`
// runs the closed-form calibration (Eq. 1-9) on a calibration-manoeuvre data set,
// `asoc-tables` reproduces Tables I and II. Fitting, comparing, diagnosing and generalising an
// ASOC data set go through the generic commands (the asoc model, models/asoc/asoc_robot_model.h).

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

namespace fitcal::tools {

struct AsocSimulateOptions {
  std::string out;
  std::uint64_t seed = 1;
  int excursions = 5;  // random-excursion runs (repetitions 1..N), the fit's training data
  double wheel_slip_sigma = 0.0;
  bool force = false;
};

struct AsocGeometricOptions {
  std::string logs;
  std::string out = "calibrated_asoc.yaml";
  bool no_output = false;
  bool force = false;  // replace an --out holding another robot's calibration
  bool allow_outside_paths = false;
};

struct AsocTablesOptions {
  int sets = 1000;
  std::uint64_t seed = 1;
  double wheel_slip_sigma = 0.0;
  int threads = 0;
};

int RunAsocSimulate(const AsocSimulateOptions& options);
int RunAsocGeometric(const AsocGeometricOptions& options);
int RunAsocTables(const AsocTablesOptions& options);

// Declare every flag of each subcommand on it, bound to the options.
void AddAsocSimulateOptions(CLI::App& app, AsocSimulateOptions& options);
void AddAsocGeometricOptions(CLI::App& app, AsocGeometricOptions& options);
void AddAsocTablesOptions(CLI::App& app, AsocTablesOptions& options);

}  // namespace fitcal::tools
