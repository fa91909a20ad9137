#pragma once
// ASOC subcommands (Doebbler et al.): `asoc-simulate` writes an ASOC data set, `asoc-geometric`
// writes the closed-form calibration (Eq. 1-9) through fit's gate (a thin wrapper of `fit`),
// `asoc-tables` reproduces Tables I and II. Fitting, comparing, diagnosing and generalising an
// ASOC data set go through the generic commands (the asoc model, models/asoc/asoc_robot_model.h).

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "cli/fit_command.h"

namespace fitcal::tools {

struct AsocSimulateOptions {
  std::string out;
  std::uint64_t seed = 1;
  int excursions = 5;  // random-excursion runs (repetitions 1..N), the fit's training data
  double wheel_slip_sigma = 0.0;
  bool force = false;
};

struct AsocTablesOptions {
  int sets = 1000;
  std::uint64_t seed = 1;
  double wheel_slip_sigma = 0.0;
  int threads = 0;
};

int RunAsocSimulate(const AsocSimulateOptions& options);
// `fit` with the robot's closed forms alone as candidates (ASOC's Eq. 1-9; any model's closed
// forms): the same request, gate, never-worse judgement, record and printout as `fit`.
int RunAsocGeometric(const FitCommandOptions& options);
int RunAsocTables(const AsocTablesOptions& options);

// Declare every flag of each subcommand on it, bound to the options.
void AddAsocSimulateOptions(CLI::App& app, AsocSimulateOptions& options);
void AddAsocGeometricOptions(CLI::App& app, FitCommandOptions& options);
void AddAsocTablesOptions(CLI::App& app, AsocTablesOptions& options);

}  // namespace fitcal::tools
