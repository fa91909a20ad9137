#include "tools/model_fit_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <unordered_map>

#include "diagnosis/channel_order_check.h"
#include "fit/final_pose_errors.h"
#include "fit/model_fit.h"
#include "fit/result_gate.h"
#include "fit/segment_cost.h"
#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/calibration_block.h"
#include "tools/fit_methods.h"
#include "tools/output_guard.h"
#include "validation/run_split.h"
#include "validation/training_runs.h"

namespace fitcal::tools {

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// How the training runs were chosen, for messages: --train-trajectories or --train-reps.
std::string TrainingSelection(const FitCommandOptions& o) {
  if (!o.train_trajectories.empty()) return "trajectories matching '" + o.train_trajectories + "'";
  return "repetitions " + o.train_reps;
}

void PrintCfTable(const RobotModelInterface& model, const std::vector<double>& selected,
                  const RunSplit& split, int threads) {
  const auto& nominal = model.robot().nominal;
  const auto row = [&](const char* name, const std::vector<AlignedRun>& runs) {
    const FinalPoseErrors before = EvaluateFinalPoseErrors(model, nominal, runs, threads);
    const FinalPoseErrors after = EvaluateFinalPoseErrors(model, selected, runs, threads);
    const double change = before.cf > 0.0 ? 100.0 * (after.cf - before.cf) / before.cf : 0.0;
    std::printf("  %-30s %10.4f %10.4f %+8.1f%%\n", name, before.cf, after.cf, change);
    std::printf("  %-30s %10.4f %10.4f\n", "  mean final position error [m]",
                before.mean_position_error_m, after.mean_position_error_m);
    std::printf("  %-30s %10.3f %10.3f\n", "  mean final heading error [deg]",
                RadToDeg(before.mean_abs_heading_error_rad),
                RadToDeg(after.mean_abs_heading_error_rad));
  };
  std::printf("  %-30s %10s %10s %9s\n", "CF (Eq. 14, m and rad)", "nominal", "calibrated",
              "change");
  row("training", split.training);
  if (!split.validation.empty()) row("validation", split.validation);
}

void PrintParameters(const Robot& robot, const std::vector<double>& p, const ModelFitResult& fit) {
  std::printf("\n  %-22s %12s %12s %12s %12s\n", "parameter", "nominal", "calibrated", "+-1 sigma",
              "change");
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const ParameterInfo& info = robot.parameters[k];
    const double s = info.DisplayScale();
    char sigma[32] = "-";
    if (fit.has_covariance && !fit.held[k])
      std::snprintf(sigma, sizeof sigma, "%.2g", fit.sigma[k] * s);
    // Angles change by degrees, lengths by percent (a percentage of an angle means nothing).
    char change[32];
    if (info.unit == ParameterUnit::kAngle) {
      std::snprintf(change, sizeof change, "%+.3f deg", (p[k] - robot.nominal[k]) * s);
    } else {
      std::snprintf(change, sizeof change, "%+.2f%%",
                    100.0 * (p[k] - robot.nominal[k]) / robot.nominal[k]);
    }
    std::printf("  %-22s %12.6f %12.6f %12s %12s%s%s\n", robot.LabelOf(k).c_str(),
                robot.nominal[k] * s, p[k] * s, sigma, change, fit.at_bound[k] ? "  AT BOUND" : "",
                fit.held[k] ? "  HELD" : "");
  }
  for (const HeldParameter& h : robot.held) {
    std::printf("  held: %s (%s)\n", robot.parameters[h.index].name.c_str(), h.reason.c_str());
  }
}

// Nominal, closed forms, the fit; and when the fit held undetermined directions and held-out
// runs can judge it, the fit without the holds too (on the training runs alone it would always
// win, by fitting what the data cannot tell apart).
std::vector<CalibrationCandidate> Candidates(const RobotModelInterface& model,
                                             const RunSplit& split, const ModelFitResult& fit,
                                             const std::string& method) {
  std::vector<CalibrationCandidate> out = {{"nominal", model.robot().nominal, true}};
  for (const ClosedFormCalibration& c : model.ClosedForms(split.training)) {
    out.push_back({c.method, c.parameters, true});
  }
  out.push_back({method, fit.parameters, fit.usable || fit.stopped_early});
  if (!fit.held_directions.empty() && !split.validation.empty()) {
    out.push_back(
        {method + " without holds", fit.unconstrained_parameters, fit.unconstrained_usable});
  }
  return out;
}

}  // namespace

bool PrintGate(const std::vector<CalibrationCandidate>& candidates, const GateDecision& gate) {
  std::printf("\nresult gate, CF on %s:\n", gate.judged_on.c_str());
  for (const std::string& line : GateLines(candidates, gate)) std::printf("%s\n", line.c_str());
  if (gate.improves_on_nominal()) return true;
  std::cerr << "fitcal: no calibration beats the nominal robot on the " << gate.judged_on
            << "; nothing written\n";
  return false;
}

void RecordFitSource(const FitCommandOptions& options, const std::vector<RunLog>& logs,
                     const RunSplit& split, const std::string& method, const std::string& objective,
                     const std::string& termination, io::CalibrationSource* source) {
  io::CalibrationSource& s = *source;
  s.method = method;
  s.objective = objective + " (sigma_xy " + std::to_string(options.position_sigma_m) +
                " m, sigma_theta " + std::to_string(options.heading_sigma_deg) + " deg)";
  s.dataset = options.logs;
  s.tool_version = kVersion;
  s.termination = termination;
  s.training_repetitions = split.training_repetitions;
  s.validation_repetitions = split.validation_repetitions;
  for (const AlignedRun& run : split.training) s.training_run_ids.push_back(run.id);
  s.training_trajectories = options.train_trajectories;
  s.training_fingerprint = TrainingFingerprint(logs, s.training_run_ids);
  s.training_runs = static_cast<int>(split.training.size());
  s.validation_runs = static_cast<int>(split.validation.size());
}

namespace {

io::CalibrationBlock MakeRecord(const FitCommandOptions& options, const RobotModelInterface& model,
                                const std::vector<RunLog>& logs, const RunSplit& split,
                                const ModelFitResult& fit, const std::string& objective,
                                const std::vector<CalibrationCandidate>& candidates,
                                const GateDecision& gate) {
  const Robot& robot = model.robot();
  const std::vector<double>& p = candidates[gate.selected].parameters;
  io::CalibrationBlock r;
  RecordFitSource(options, logs, split, candidates[gate.selected].name, objective, fit.termination,
                  &r);
  r.cf_training_before =
      EvaluateFinalPoseErrors(model, robot.nominal, split.training, options.threads).cf;
  r.cf_training_after = EvaluateFinalPoseErrors(model, p, split.training, options.threads).cf;
  r.cf_validation_before =
      EvaluateFinalPoseErrors(model, robot.nominal, split.validation, options.threads).cf;
  r.cf_validation_after = EvaluateFinalPoseErrors(model, p, split.validation, options.threads).cf;
  r.selected = candidates[gate.selected].name;
  r.selected_on = gate.judged_on;
  for (const HeldParameter& h : robot.held) r.held.push_back(robot.parameters[h.index].name);
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (fit.at_bound[k]) r.at_bound.push_back(robot.parameters[k].name);
  }
  // The uncertainty is the fit's; it describes the selected parameters only when the fit won.
  r.has_uncertainty = fit.has_covariance && candidates[gate.selected].name == options.method;
  r.sigma = fit.sigma;
  r.correlation = fit.correlation;
  return r;
}

// Windows of 0.5 m of ground-truth path for the runs whose ground truth has intermediate poses
// (segments see miswirings that closed paths hide from final poses); empty lists otherwise.
std::vector<std::vector<Segment>> OrderCheckWindows(const std::vector<AlignedRun>& training,
                                                    const std::vector<RunLog>& logs) {
  std::unordered_map<std::string, const RunLog*> by_id;
  for (const RunLog& log : logs) by_id[log.id] = &log;
  SegmentOptions windows;
  windows.length_m = 0.5;
  windows.stride_fraction = 1.0;  // disjoint: independent residuals for the F test
  std::vector<std::vector<Segment>> out(training.size());
  int total = 0;
  for (std::size_t i = 0; i < training.size(); ++i) {
    out[i] = MakeSegments(training[i], by_id.at(training[i].id)->ground_truth, windows);
    total += static_cast<int>(out[i].size());
  }
  if (total < 4) out.clear();
  return out;
}

// Exit code 4 with one line when another channel order explains the runs far better.
bool ChannelsLookMiswired(const FitCommandOptions& options, const RobotModelInterface& model,
                          const std::vector<AlignedRun>& training,
                          const std::vector<RunLog>& logs) {
  ChannelOrderOptions order_options;
  order_options.weights.position_sigma_m = options.position_sigma_m;
  order_options.weights.heading_sigma_rad = DegToRad(options.heading_sigma_deg);
  order_options.num_threads = options.threads;
  const std::vector<std::vector<Segment>> windows = OrderCheckWindows(training, logs);
  ChannelOrderReport order = CheckChannelOrder(training, windows, model, order_options);
  if (!order.likely_miswired && !windows.empty()) {
    order = CheckChannelOrder(training, {}, model, order_options);
  }
  if (!order.likely_miswired) return false;
  std::cerr << "fitcal: " << options.logs << ": " << order.message
            << "; nothing written (--skip-wheel-order-check to fit anyway)\n";
  return true;
}

// The header, the CF table, the parameters and the solver's stop reason.
void PrintFit(const FitCommandOptions& options, const RobotModelInterface& model,
              const RunSplit& split, const std::vector<double>& selected, const FitMethod& method,
              const ModelFitMethodOutcome& outcome) {
  const Robot& robot = model.robot();
  const ModelFitResult& fit = outcome.fit;
  std::printf("fitcal %s  %s robot '%s'  data set %s\n", kVersion, robot.model.c_str(),
              robot.name.c_str(), options.logs.c_str());
  const std::string reps = FormatRepetitionList(split.training_repetitions);
  const std::string selection = options.train_trajectories.empty()
                                    ? "repetitions " + reps
                                    : TrainingSelection(options) + "; repetitions " + reps;
  std::printf("runs: %zu training (%s), %zu validation (repetitions %s)\n\n", split.training.size(),
              selection.c_str(), split.validation.size(),
              FormatRepetitionList(split.validation_repetitions).c_str());
  PrintCfTable(model, selected, split, options.threads);
  PrintParameters(robot, selected, fit);
  // Active-set rounds are the Ceres fit's (fit/model_fit.h); NLopt methods have none.
  const std::string rounds =
      fit.active_set_rounds > 0
          ? ", " + std::to_string(fit.active_set_rounds) + " active-set rounds"
          : "";
  std::printf("\nsolver: %s, %s after %d iterations (%d evaluations%s), %.3f s (%s)\n",
              method.description.c_str(), fit.termination.c_str(), fit.iterations,
              outcome.evaluations, rounds.c_str(), fit.solve_time_s, fit.message.c_str());
}

}  // namespace

int StoppedEarlyExit(bool selected_fit_stopped_early, const std::string& termination) {
  if (!selected_fit_stopped_early) return 0;
  std::cerr << "fitcal: warning: the written calibration is the solver's last point ("
            << termination
            << " at the iteration limit): it beats the nominal, but check it or raise "
               "--max-iterations\n";
  return 6;
}

void PrintHeldAtNominal(const std::string& direction) {
  std::printf("held at nominal, not determined by the training runs: %s\n", direction.c_str());
}

int RunModelFitCommand(const FitCommandOptions& options, const io::DatasetIndex& index,
                       const RobotModelPtr& model) {
  const auto t_total = std::chrono::steady_clock::now();
  const Robot& robot = model->robot();
  // Validated by RunFitCommand: a known method, settings in range.
  const FitMethod* method = FindFitMethod(options.method);
  FitMethodSettings settings;
  std::string error;
  if (method == nullptr || !MakeFitMethodSettings(options, options.threads, &settings, &error)) {
    std::cerr << "fitcal: " << (method == nullptr ? "unknown --method " + options.method : error)
              << "\n";
    return 2;
  }
  if (!robot.effects.empty()) {
    std::cerr << "fitcal: " << index.robot_path
              << ": the robot declares effects that 'fit' does not model; refit them with "
                 "'fitcal diagnose', or start from a robot YAML without an effects: list\n";
    return 2;
  }
  if (!options.no_output && !options.force) {
    const std::string refusal = OverwriteRefusal(options.out, robot.name);
    if (!refusal.empty()) {
      return Refuse(refusal);
    }
  }
  const io::Dataset dataset = LoadRuns(options, index, &robot);
  io::StopHereForTests("loaded");
  const RunSplit split =
      SplitForFit(AlignRuns(dataset.runs), options.train_reps, options.train_trajectories);
  const double load_s = Seconds(t_total);
  if (split.training.empty()) {
    std::cerr << "fitcal: no run of " << options.logs << " is a training run ("
              << TrainingSelection(options) << ")\n";
    return 2;
  }
  if (!options.skip_wheel_order_check &&
      ChannelsLookMiswired(options, *model, split.training, dataset.runs)) {
    return 4;
  }
  const ModelFitMethodOutcome outcome = method->run_model(split.training, *model, settings);
  const ModelFitResult& fit = outcome.fit;
  const std::vector<CalibrationCandidate> candidates =
      Candidates(*model, split, fit, options.method);
  const GateDecision gate =
      SelectCalibration(*model, candidates, split.training, split.validation, options.threads);
  const std::vector<double>& selected = candidates[gate.selected].parameters;

  PrintFit(options, *model, split, selected, *method, outcome);
  if (!fit.has_covariance) std::printf("uncertainty: %s\n", fit.covariance_message.c_str());
  for (const UndeterminedDirection& d : fit.held_directions) PrintHeldAtNominal(d.description);
  if (!PrintGate(candidates, gate)) return 5;
  if (!options.no_output) {
    const io::CalibrationBlock record =
        MakeRecord(options, *model, dataset.runs, split, fit, outcome.objective, candidates, gate);
    io::StopHereForTests("fitted");
    io::WriteFileAtomically(options.out,
                            model->RobotYaml(selected, io::CalibrationBlockYaml(record, robot)));
    std::printf("wrote %s\n", options.out.c_str());
  }
  std::printf("time: load %.3f s, total %.3f s\n", load_s, Seconds(t_total));
  return StoppedEarlyExit(fit.stopped_early && candidates[gate.selected].name == options.method,
                          fit.termination);
}

}  // namespace fitcal::tools
