#include "tools/fit_command.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <regex>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "diagnosis/degenerate_data.h"
#include "diagnosis/identifiability.h"
#include "diagnosis/wheel_order_check.h"
#include "fit/correlation.h"
#include "fit/final_pose_cost.h"
#include "fit/omni3_ceres_fit.h"
#include "fit/result_gate.h"
#include "fit/run_split.h"
#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/dataset.h"
#include "io/input_error.h"
#include "io/robot_yaml.h"
#include "io/yaml_reader.h"
#include "models/model_registry.h"
#include "models/omni3/omni3_robot_model.h"
#include "tools/cli_validators.h"
#include "tools/fit_methods.h"
#include "tools/model_fit_command.h"
#include "tools/output_guard.h"
#include "tools/sim/flower_candidates.h"
#include "validation/propagated_uncertainty.h"
#include "validation/residual_dof.h"
#include "validation/training_runs.h"

namespace fitcal::tools {

namespace {

// The training runs whose ground truth has poses between the start and the end (at least three
// inside the run's window), with their tracks.
void SelectRunsWithIntermediateGroundTruth(const std::vector<AlignedRun>& training,
                                           const std::vector<RunLog>& logs,
                                           std::vector<AlignedRun>* runs,
                                           std::vector<const GroundTruthTrack*>* tracks) {
  std::unordered_map<std::string, const RunLog*> by_id;
  for (const RunLog& log : logs) by_id[log.id] = &log;
  for (const AlignedRun& run : training) {
    const auto it = by_id.find(run.id);
    if (it == by_id.end()) continue;
    const GroundTruthTrack& gt = it->second->ground_truth;
    const auto inside = std::count_if(gt.t_s.begin(), gt.t_s.end(), [&](double t) {
      return t >= run.t_start_s && t <= run.t_final_s;
    });
    if (inside < 3) continue;
    runs->push_back(run);
    tracks->push_back(&gt);
  }
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

double ChangePercent(double before, double after) {
  return before > 0.0 ? 100.0 * (after - before) / before : 0.0;
}

void PrintParameters(const Omni3Robot& robot, const Omni3FitResult& fit) {
  const auto nominal = robot.nominal.ToArray();
  static const char* kSymbol[] = {"R", "r", "delta"};
  static const char* kUnit[] = {"m", "m", "deg"};
  std::printf("\n  %-12s %12s %12s %12s %10s\n", "parameter", "nominal", "calibrated", "+-1 sigma",
              "change");
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    const int group = k / omni3::kNumWheels;
    const double scale = group == 2 ? 180.0 / M_PI : 1.0;
    char name[48];
    std::snprintf(name, sizeof name, "%s_%s [%s]", kSymbol[group],
                  robot.wheel_names[k % omni3::kNumWheels].c_str(), kUnit[group]);
    char sigma[32] = "-";
    if (fit.has_covariance) std::snprintf(sigma, sizeof sigma, "%.2g", fit.sigma[k] * scale);
    const int digits = group == 2 ? 4 : 6;
    std::printf("  %-12s %12.*f %12.*f %12s %+9.2f%%%s\n", name, digits, nominal[k] * scale, digits,
                fit.parameters[k] * scale, sigma, ChangePercent(nominal[k], fit.parameters[k]),
                fit.at_bound[k] ? "  AT BOUND" : "");
  }
}

}  // namespace

void AddFitOptions(CLI::App& app, FitCommandOptions& o) {
  AddDatasetOptions(app, o, LogsFlag::kCheckedByCommand);
  app.add_option("--method", o.method, "Solver: " + FitMethodNames())->capture_default_str();
  AddSolverOptions(app, o);
  CLI::Option* reps =
      app.add_option("--train-reps", o.train_reps,
                     "Repetitions used for fitting, e.g. 1-5 or 1,3,5; the others validate")
          ->capture_default_str()
          ->check(RepetitionListValidator());
  app.add_option("--train-trajectories", o.train_trajectories,
                 "Fit on the runs whose trajectory label matches (list or regular expression); "
                 "the others validate")
      ->excludes(reps);
  app.add_option("--out", o.out, "Calibrated robot YAML to write (atomically)")
      ->capture_default_str();
  app.add_flag("--no-output", o.no_output, "Do not write the calibrated YAML");
  app.add_flag("--force", o.force, "Overwrite --out even if it holds another robot's calibration");
  app.add_option("--time-blocks", o.time_blocks,
                 "With one or two runs fitted on their tracks and none held out, judge on time: "
                 "cut each into this many blocks of equal path, fit the odd blocks and judge on "
                 "the even ones and back; the whole runs' fit is written only when that beats "
                 "the nominal")
      ->capture_default_str()
      ->check(CLI::Range(2, 100));
  app.add_flag("--skip-wheel-order-check", o.skip_wheel_order_check,
               "Fit even if another encoder column order/sign explains the data far better");
  app.add_option("--effects", o.effects,
                 "Library effects to fit with the parameters on the ground-truth tracks (e.g. "
                 "pivot_yaw_gain), one more candidate of the result gate; an effect the robot "
                 "YAML declares is refitted without naming it")
      ->delimiter(',');
}

namespace {

// --residuals auto on omni3's own path: whether the training runs call for track residuals (then
// the seam's fit takes over; it resolves auto the same way).
bool ResolvesToTrack(const FitCommandOptions& options, const io::Dataset& dataset,
                     FitMethodSettings* settings) {
  const RunSplit split =
      SplitForFit(AlignRuns(dataset.runs), options.train_reps, options.train_trajectories);
  std::unordered_map<std::string, const GroundTruthTrack*> track_of;
  for (const RunLog& log : dataset.runs) track_of[log.id] = &log.ground_truth;
  std::vector<const GroundTruthTrack*> tracks;
  for (const AlignedRun& run : split.training) tracks.push_back(track_of.at(run.id));
  FitMethodSettings resolved = *settings;
  ResolveAutoResiduals(split.training, tracks, options.method, &resolved);
  return resolved.residuals != ResidualKind::kFinalPose;
}

}  // namespace

int RunFitCommand(const FitCommandOptions& options) {
  if (options.logs.empty()) {
    std::cerr << "fitcal: --logs <data set directory> is required (see fitcal --help)\n";
    return 2;
  }
  const auto t_total = std::chrono::steady_clock::now();
  const FitMethod* method = FindFitMethod(options.method);
  if (method == nullptr) {
    std::cerr << "fitcal: unknown --method '" << options.method
              << "' (available: " << FitMethodNames() << ")\n";
    return 2;
  }
  FitMethodSettings settings;
  std::string settings_error;
  if (!MakeFitMethodSettings(options, options.threads, &settings, &settings_error)) {
    std::cerr << "fitcal: " << settings_error << "\n";
    return 2;
  }
  return RunReportingErrors("fitcal", [&]() -> int {
    const auto t_load = std::chrono::steady_clock::now();
    const OpenedDataset opened = OpenDataset(options);
    const io::DatasetIndex& index = opened.index;
    if (!options.no_output) {
      // Every model's fit writes one file: never over one of its own inputs (exit 2, usage).
      const std::string refusal = OutputFileRefusal(options.out, opened.inputs);
      if (!refusal.empty()) return Refuse(refusal);
    }
    // Every model on the seam except omni3, whose fit (with its NLopt methods and fast kernel)
    // still has its own path below - which fits Eq. 4 to final poses alone: omni3 with effects
    // or with track residuals takes the seam's.
    const RobotModelPtr model = ReadRobotModelFile(index.robot_path);
    if (model->robot().model != "omni3" || !options.effects.empty() ||
        !model->robot().effects.empty() ||
        (!settings.residuals_auto && settings.residuals != ResidualKind::kFinalPose)) {
      return RunModelFitCommand(options, index, model);
    }
    const io::Dataset dataset = LoadRuns(options, index, /*robot=*/nullptr);
    if (settings.residuals_auto && ResolvesToTrack(options, dataset, &settings)) {
      return RunModelFitCommand(options, index, model);
    }
    io::StopHereForTests("loaded");
    const Omni3Robot robot = io::ReadOmni3Robot(dataset.robot_path);
    if (!options.no_output && !options.force) {
      const std::string refusal = OverwriteRefusal(options.out, robot.name);
      if (!refusal.empty()) {
        return Refuse(refusal);
      }
    }
    RunSplit split =
        SplitForFit(AlignRuns(dataset.runs), options.train_reps, options.train_trajectories);
    const double load_s = Seconds(t_load);
    if (split.training.empty()) {
      std::cerr << "fitcal: no run of " << options.logs << " is a training run ("
                << (options.train_trajectories.empty()
                        ? "repetitions " + options.train_reps
                        : "trajectories matching '" + options.train_trajectories + "'")
                << ")\n";
      return 2;
    }

    if (const std::string refusal =
            FinalPoseDofRefusal(split.training.size(), robot.nominal.ToArray().size());
        !refusal.empty()) {
      std::cerr << "fitcal: " << options.logs << ": " << refusal << "\n";
      return 1;
    }
    // Before fitting, as a fit would not notice them: rates in the wrong unit, miswired encoder
    // columns, data that cannot determine the parameters.
    const RateUnitsReport units = CheckRateUnits(dataset.runs, robot);
    if (units.suspicious)
      std::cerr << "fitcal: warning: " << options.logs << ": " << units.message << "\n";
    if (!units.suspicious && !options.skip_wheel_order_check) {
      WheelOrderOptions order_options;
      order_options.weights = options.Weights();
      order_options.num_threads = options.threads;
      // With intermediate ground truth the segment test decides (closed paths hide some
      // miswirings from final poses, and segments name the mapping more sharply); final poses
      // cover the runs without it, or data too short for segments.
      std::vector<AlignedRun> tracked;
      std::vector<const GroundTruthTrack*> tracks;
      SelectRunsWithIntermediateGroundTruth(split.training, dataset.runs, &tracked, &tracks);
      WheelOrderReport order;
      if (!tracked.empty())
        order = CheckWheelOrderOnSegments(tracked, tracks, robot, order_options);
      const bool segments_decided = order.degrees_of_freedom > 0;
      if (!order.likely_miswired && (!segments_decided || tracked.size() < split.training.size())) {
        order = CheckWheelOrder(split.training, robot, order_options);
      }
      if (order.likely_miswired) {
        std::cerr << "fitcal: " << options.logs << ": " << order.message
                  << "; nothing written (--skip-wheel-order-check to fit anyway)\n";
        return 4;
      }
    }
    for (const std::string& problem : FindDegenerateData(split.training, robot)) {
      std::printf("warning: %s\n", problem.c_str());
    }

    const FitMethodOutcome outcome = method->run(split.training, robot, settings);
    const Omni3FitResult& fit = outcome.fit;

    const auto nominal = robot.nominal.ToArray();
    const FinalPoseErrors train_before =
        EvaluateFinalPoseErrors(nominal, split.training, options.threads);
    const FinalPoseErrors train_after =
        EvaluateFinalPoseErrors(fit.parameters, split.training, options.threads);
    const FinalPoseErrors val_before =
        EvaluateFinalPoseErrors(nominal, split.validation, options.threads);
    const FinalPoseErrors val_after =
        EvaluateFinalPoseErrors(fit.parameters, split.validation, options.threads);

    std::printf("fitcal %s  omni3 robot '%s'  data set %s\n", kVersion, robot.name.c_str(),
                options.logs.c_str());
    std::printf("runs: %zu training (repetitions %s), %zu validation (repetitions %s)\n\n",
                split.training.size(), FormatRepetitionList(split.training_repetitions).c_str(),
                split.validation.size(),
                FormatRepetitionList(split.validation_repetitions).c_str());
    std::printf("  %-30s %10s %10s %9s\n", "CF (Eq. 14, m and rad)", "nominal", "calibrated",
                "change");
    std::printf("  %-30s %10.4f %10.4f %+8.1f%%\n", "training", train_before.cf, train_after.cf,
                ChangePercent(train_before.cf, train_after.cf));
    if (!split.validation.empty()) {
      std::printf("  %-30s %10.4f %10.4f %+8.1f%%\n", "validation", val_before.cf, val_after.cf,
                  ChangePercent(val_before.cf, val_after.cf));
      std::printf("  %-30s %10.4f %10.4f\n", "  mean final position error [m]",
                  val_before.mean_position_error_m, val_after.mean_position_error_m);
      std::printf("  %-30s %10.3f %10.3f\n", "  mean final heading error [deg]",
                  val_before.mean_abs_heading_error_rad * 180.0 / M_PI,
                  val_after.mean_abs_heading_error_rad * 180.0 / M_PI);
    } else {
      std::printf("  validation: no held-out repetitions; the result is not validated\n");
    }
    PrintParameters(robot, fit);
    {
      std::vector<std::string> ids;
      for (const AlignedRun& run : split.training) ids.push_back(run.id);
      for (const OutlierRun& o : FindOutlierRuns(ids, train_after.per_run_cf)) {
        std::printf(
            "warning: run %s: final-pose error %.1fx the median run's (gross wheel slip "
            "or a ground truth of another run?); a robust loss limits its pull\n",
            o.id.c_str(), o.error_ratio);
      }
    }
    std::printf("\nsolver: %s, %s after %d iterations (%d evaluations), %.3f s (%s)\n",
                method->description.c_str(), fit.termination.c_str(), fit.iterations,
                outcome.evaluations, fit.solve_time_s, fit.message.c_str());
    if (!fit.has_covariance) std::printf("uncertainty: %s\n", fit.covariance_message.c_str());
    for (const std::string& d : fit.held_directions) PrintHeldAtNominal(d);
    if (fit.usable) {  // name what the training runs cannot determine (Eq. 14's Jacobian)
      const ResidualWeights weights = options.Weights();
      const IdentifiabilityReport ident = AnalyseIdentifiability(
          FinalPoseJacobian(fit.parameters, split.training, weights, options.threads),
          fit.parameters, sim::FlowerCandidateMotions(), nominal, weights);
      // The advice names flower trajectories (R/G/B families): only for data sets that have them.
      const bool flower =
          std::any_of(split.training.begin(), split.training.end(), [](const AlignedRun& run) {
            return std::regex_match(run.trajectory, std::regex("[RGB][0-9]+"));
          });
      for (const std::string& line : IdentifiabilityLines(ident)) {
        if (flower || line.find("would be fixed by adding") == std::string::npos) {
          std::printf("%s\n", line.c_str());
        }
      }
    }
    for (int k = 0; k < omni3::kNumParameters; ++k) {
      if (fit.at_bound[k]) {
        std::printf(
            "warning: a parameter stopped on its bound; the model may be absorbing an "
            "effect it does not contain, or the bounds are too tight\n");
        break;
      }
    }
    if (!fit.usable && !fit.stopped_early) {
      std::cerr << "fitcal: the fit did not converge (" << fit.termination << ": " << fit.message
                << "); nothing written\n";
      return 3;
    }
    // The result gate (fit/result_gate.h): the fit is written only if it beats the nominal
    // robot on the held-out runs (on the training runs, said so, when there are none).
    // With held directions and held-out runs, the fit without the holds competes too (as in
    // model_fit_command.cc).
    std::vector<CalibrationCandidate> candidates = {
        {"nominal", std::vector<double>(nominal.begin(), nominal.end()), true},
        {method->name, std::vector<double>(fit.parameters.begin(), fit.parameters.end()),
         fit.usable || fit.stopped_early}};
    if (!fit.held_directions.empty() && !split.validation.empty()) {
      candidates.push_back({method->name + " without holds",
                            std::vector<double>(fit.unconstrained_parameters.begin(),
                                                fit.unconstrained_parameters.end()),
                            fit.unconstrained_usable});
    }
    const GateDecision gate = SelectCalibration(*Omni3ModelOf(robot), candidates, split.training,
                                                split.validation, options.threads);
    if (!PrintGate(candidates, gate)) return 5;

    if (!options.no_output) {
      // What the gate selected (the fit, or the fit without its holds) is written, with the CF
      // that `fitcal report` measures for it; the fit's uncertainty only when the fit won.
      const double* selected = candidates[gate.selected].parameters.data();
      const bool fit_won = gate.selected == 1;
      Omni3Robot calibrated = robot;
      calibrated.nominal = omni3::Parameters::FromArray(selected);
      io::CalibrationRecord record;
      RecordFitSource(options, dataset.runs, split, candidates[gate.selected].name,
                      outcome.objective, fit.termination, &record);
      for (int k = 0; k < omni3::kNumParameters; ++k) {
        if (fit_won && fit.at_bound[k]) record.at_bound.push_back(ParameterName(k));
      }
      Omni3ParameterArray selected_array;
      std::copy(selected, selected + omni3::kNumParameters, selected_array.begin());
      record.cf_training_before = train_before.cf;
      record.cf_training_after =
          fit_won ? train_after.cf
                  : EvaluateFinalPoseErrors(selected_array, split.training, options.threads).cf;
      record.cf_validation_before = val_before.cf;
      record.cf_validation_after = fit_won ? val_after.cf : gate.cf[gate.selected];
      record.has_uncertainty = fit.has_covariance && fit_won;
      record.sigma = fit.sigma;
      record.correlation = fit.correlation;
      if (!record.has_uncertainty) {  // never sigma: null (validation/propagated_uncertainty.h)
        const PropagatedUncertainty u = PropagateFinalPoseUncertainty(
            *Omni3ModelOf(robot), candidates[gate.selected].parameters, split.training);
        if (!u.ok) {
          std::cerr << "fitcal: no uncertainty for the selected calibration (" << u.message
                    << "); nothing written\n";
          return 1;
        }
        record.has_uncertainty = true;
        std::copy(u.sigma.begin(), u.sigma.end(), record.sigma.begin());
        record.correlation = CorrelationOf(u.covariance);
      }
      record.inverse_kinematic_matrix = omni3::InverseKinematicMatrix(selected);
      io::StopHereForTests("fitted");
      io::WriteFileAtomically(options.out, io::Omni3RobotYaml(calibrated, &record));
      std::printf("wrote %s\n", options.out.c_str());
    }
    std::printf("time: load %.3f s, total %.3f s\n", load_s, Seconds(t_total));
    return StoppedEarlyExit(fit.stopped_early && gate.selected == 1, fit.termination);
  });
}

}  // namespace fitcal::tools
