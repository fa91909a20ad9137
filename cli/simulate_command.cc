#include "cli/simulate_command.h"
#include "cli/cli_validators.h"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "cli/dataset_command.h"
#include "io/output_guard.h"
#include "sim/model_dataset.h"

namespace fitcal::tools {

namespace {

// "repetitions" / "excursions" for one: the unit without its plural s.
std::string Singular(const std::string& unit, int count) {
  const bool plural_s = count == 1 && !unit.empty() && unit.back() == 's';
  return plural_s ? unit.substr(0, unit.size() - 1) : unit;
}

// "name=v1[,v2]" -> an effect of the registry with its values, checked against its bounds.
effects::EffectValue ParseInjectedEffect(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos)
    throw std::invalid_argument("--inject '" + text + "': expected name=value[,value]");
  effects::EffectValue e;
  e.id = effects::EffectIdFromName(text.substr(0, eq));
  const effects::EffectInfo& info = effects::Info(e.id);
  std::string rest = text.substr(eq + 1);
  for (int k = 0; k < info.num_parameters; ++k) {
    const std::size_t comma = rest.find(',');
    const std::optional<double> value = WholeTextNumber(rest.substr(0, comma));
    e.value[k] = value.value_or(0.0);
    if (!value || !(e.value[k] >= info.lower[k] && e.value[k] <= info.upper[k])) {
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

// The nominal and the true value of each parameter, in display units.
void PrintTruth(const Robot& robot, const std::vector<double>& truth) {
  std::printf("  %-22s %12s %12s\n", "parameter", "nominal", "true");
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const double s = robot.parameters[k].DisplayScale();
    std::printf("  %-22s %12.6f %12.6f%s\n", robot.LabelOf(k).c_str(), robot.nominal[k] * s,
                truth[k] * s, robot.IsHeld(k) ? "  held (gauge)" : "");
  }
}

// The flags as a request of the library, which decides what the model's scenario takes: a noise
// flag not given leaves the model recorder's value.
sim::ModelDatasetRequest RequestOf(const SimulateCommandOptions& options) {
  const auto given = [&](const char* flag) { return options.given.count(flag) > 0; };
  const auto if_given = [&](const char* flag, auto value) {
    return given(flag) ? std::optional(value) : std::nullopt;
  };
  sim::ModelDatasetRequest r;
  r.out = options.out;
  r.model = options.model;
  r.robot = given("--robot") || options.model.empty() ? options.robot : "";
  r.truth = options.truth;
  r.force = options.force;
  r.noise.repetitions = if_given("--repetitions", options.repetitions);
  r.noise.seed = options.seed;
  r.noise.ticks_per_rev = if_given("--encoder-counts-per-rev", options.encoder_counts_per_rev);
  r.noise.wheel_rate_sigma_rad_s =
      if_given("--wheel-rate-sigma-rad-s", options.wheel_rate_sigma_rad_s);
  r.noise.wheel_relative_sigma = if_given("--wheel-slip-sigma", options.wheel_slip_sigma);
  r.noise.angle_sigma_rad = if_given("--angle-sigma-deg", options.angle_sigma_deg * M_PI / 180.0);
  r.noise.gt_position_sigma_m = if_given("--gt-position-sigma-m", options.gt_position_sigma_m);
  r.noise.gt_heading_sigma_rad =
      if_given("--gt-heading-sigma-deg", options.gt_heading_sigma_deg * M_PI / 180.0);
  r.noise.slip_sigma = if_given("--slip-sigma", options.slip_sigma);
  for (const std::string& text : options.inject) {
    r.noise.injected_effects.push_back(ParseInjectedEffect(text));
  }
  return r;
}

}  // namespace

void AddSimulateOptions(CLI::App& app, SimulateCommandOptions& o) {
  app.add_option("--out", o.out, "Output data set directory")->required();
  app.add_option(
      "--model", o.model,
      "Robot model (" + sim::ScenarioModelNames() + "; default: the --robot's model)");
  app.add_option("--robot", o.robot, "Nominal robot YAML (commands and fit start)")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  app.add_option("--truth", o.truth,
                 "Robot YAML of the true robot (default: the scenario's, docs/simulate.md)")
      ->check(CLI::ExistingFile);
  // The recorder's values below are the model's unless given (docs/simulate.md).
  app.add_option("--repetitions", o.repetitions,
                 "Repetitions of each trajectory (default: the model's scenario, docs/simulate.md)")
      ->check(NonNegativeNumber());
  app.add_option("--seed", o.seed, "Random seed")->capture_default_str();
  app.add_option("--encoder-counts-per-rev", o.encoder_counts_per_rev,
                 "Encoder resolution (default: the model's recorder)");
  app.add_option("--gt-position-sigma-m", o.gt_position_sigma_m,
                 "Ground-truth position noise (m; default: the model's recorder)")
      ->check(NonNegativeNumber());
  app.add_option("--gt-heading-sigma-deg", o.gt_heading_sigma_deg,
                 "Ground-truth heading noise (deg; default: the model's recorder)")
      ->check(NonNegativeNumber());
  app.add_option("--slip-sigma", o.slip_sigma, "Relative wheel slip noise (stepped physics)")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  app.add_option("--wheel-slip-sigma", o.wheel_slip_sigma,
                 "perfect tracking: relative noise on each wheel's advance per encoder interval "
                 "(default: the model's recorder)")
      ->check(NonNegativeNumber());
  app.add_option("--wheel-rate-sigma-rad-s", o.wheel_rate_sigma_rad_s,
                 "perfect tracking: white noise on each interval's mean wheel rate (rad/s; "
                 "default: the model's recorder)")
      ->check(NonNegativeNumber());
  app.add_option("--angle-sigma-deg", o.angle_sigma_deg,
                 "--model: noise of an angle channel's readings, e.g. steering (deg; default: "
                 "the model's recorder)")
      ->check(NonNegativeNumber());
  app.add_flag("--force", o.force, io::kForceDirectoryHelp);
  app.add_option("--inject", o.inject,
                 "Inject a library effect, name=value[,value] (docs/simulate.md); repeatable; "
                 "the data set does not name it");
  RecordGivenFlags(app, &o.given);
}

int RunSimulateCommand(const SimulateCommandOptions& options) {
  return RunReportingErrors("fitcal simulate", [&]() -> int {
    const sim::ModelDatasetRequest r = RequestOf(options);
    const sim::WrittenModelDataset written = sim::WriteModelDataset(r);
    const Robot& robot = written.model->robot();
    const std::string unit = Singular(written.repetition_unit, written.repetitions);
    std::printf("wrote %zu runs of the %s robot '%s' (%d %s, seed %llu) to %s\n",
                written.num_runs, robot.model.c_str(), robot.name.c_str(), written.repetitions,
                unit.c_str(), static_cast<unsigned long long>(r.noise.seed), options.out.c_str());
    PrintTruth(robot, written.truth);
    return 0;
  });
}

}  // namespace fitcal::tools
