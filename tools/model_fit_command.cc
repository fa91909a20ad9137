#include "tools/model_fit_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "diagnosis/channel_order_check.h"
#include "diagnosis/degenerate_data.h"
#include "fit/correlation.h"
#include "fit/effect_fit.h"
#include "fit/final_pose_errors.h"
#include "fit/model_fit.h"
#include "fit/motion_advice.h"
#include "fit/result_gate.h"
#include "fit/run_split.h"
#include "fit/segment_cost.h"
#include "fitcal/version.h"
#include "io/atomic_file.h"
#include "io/calibration_block.h"
#include "models/mounted_model.h"
#include "tools/effect_list.h"
#include "tools/everyday_driving_table.h"
#include "tools/fit_methods.h"
#include "tools/output_guard.h"
#include "tools/tying_flags.h"
#include "validation/held_out_halves.h"
#include "validation/never_worse.h"
#include "validation/propagated_uncertainty.h"
#include "validation/rate_units.h"
#include "validation/residual_dof.h"
#include "validation/residual_kind_transfer.h"
#include "validation/statistics.h"
#include "validation/track_objective_transfer.h"
#include "validation/training_runs.h"
#include "validation/trajectory_family.h"
#include "validation/trajectory_metrics.h"

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

// The final-pose errors of a candidate of the gate on some runs: replayed by the model alone, or
// with its effects against each run's ground-truth track (the same Eq. 14 at the same poses).
class CandidateErrors {
 public:
  CandidateErrors(const RobotModelInterface& model, int threads)
      : model_(model), threads_(threads) {}

  FinalPoseErrors operator()(const CalibrationCandidate& c,
                             const std::vector<AlignedRun>& runs) const {
    if (c.effects.empty()) return EvaluateFinalPoseErrors(model_, c.parameters, runs, threads_);
    return EvaluateFinalPoseErrors(model_, c.parameters, c.effects, runs, TracksOf(runs), threads_);
  }

  EffectCandidateCf Cf() const {
    return [this](const CalibrationCandidate& c, const std::vector<AlignedRun>& runs) {
      return (*this)(c, runs).cf;
    };
  }

 private:
  const RobotModelInterface& model_;
  int threads_;
};

void PrintCfTable(const CalibrationCandidate& nominal, const CalibrationCandidate& selected,
                  const RunSplit& split, const CandidateErrors& errors) {
  const auto row = [&](const char* name, const std::vector<AlignedRun>& runs) {
    const FinalPoseErrors before = errors(nominal, runs);
    const FinalPoseErrors after = errors(selected, runs);
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

// What the parameter table and the calibration record say of the selected candidate: the
// uncertainty, bound contacts and holds of the fit that made it (none for the nominal or a
// closed form; a fit's bound contacts also for the fit without its holds).
struct SelectedFit {
  bool has_covariance = false;
  std::vector<double> sigma;
  Eigen::MatrixXd correlation;
  std::vector<bool> at_bound, held;  // per parameter
  std::string objective, termination;
  // The weights' noise levels when the fit estimated them (fit/noise_levels.h); else not estimated.
  NoiseLevels noise_levels;
};

constexpr const char* kTrackObjective = "sum over runs of the mean squared track error (m and rad)";

// The fits on the training tracks when effects are fitted (fit/effect_fit.h): the
// parameters alone and with the effects, on one objective, so that the effects are judged like
// for like; with their indices among the gate's candidates.
struct TrackFits {
  EffectFitResult without_effects, with_effects;
  int without_index = -1, with_index = -1;
};

SelectedFit DescribeSelected(const Robot& robot,
                             const std::vector<CalibrationCandidate>& candidates,
                             int selected_index, const std::string& method,
                             const std::string& method_objective, const ModelFitResult& fit,
                             const std::optional<TrackFits>& track_fits) {
  const CalibrationCandidate& selected = candidates[selected_index];
  const std::size_t n = robot.nominal.size();
  SelectedFit out{false,
                  {},
                  {},
                  std::vector<bool>(n, false),
                  std::vector<bool>(n, false),
                  method_objective,
                  fit.termination,
                  {}};
  const EffectFitResult* track_fit = nullptr;
  if (track_fits && selected_index == track_fits->with_index) {
    track_fit = &track_fits->with_effects;
  } else if (track_fits && selected_index == track_fits->without_index) {
    track_fit = &track_fits->without_effects;
  }
  if (track_fit != nullptr) {
    out.has_covariance = track_fit->has_covariance;
    out.sigma = track_fit->sigma;
    out.correlation = track_fit->correlation;
    // The effect fit reports only whether some parameter ended on a bound: which ones, by the
    // fit's own rule.
    out.at_bound = ParametersAtBound(robot, selected.parameters);
    for (const HeldParameter& h : robot.held) out.held[h.index] = true;
    out.objective = kTrackObjective;
    out.termination = track_fit->termination;
  } else if (selected.name == method) {
    out.noise_levels = fit.noise_levels;
    out.has_covariance = fit.has_covariance;
    out.sigma = fit.sigma;
    out.correlation = fit.correlation;
    out.at_bound = fit.at_bound;
    out.held = fit.held;
  } else if (selected.name == method + " without holds") {
    out.at_bound = fit.at_bound;
    out.held = fit.held;  // the parameters' holds (gauge, --hold) stay; the directions' go
  }
  return out;
}

// A closed form's own sigmas (ClosedFormCalibration::sigma, e.g. ASOC's spread over hold runs)
// for the parameters it measures, r_c and beta included, which the final-pose residuals cannot
// see (the robot holds them). Their correlation with the others is not estimated: written as 0.
// True when it measured every parameter.
bool UseOwnSigmas(const std::vector<double>& own, SelectedFit* fit) {
  if (own.empty()) return false;
  const auto n = static_cast<Eigen::Index>(own.size());
  if (!fit->has_covariance) {
    fit->sigma.assign(own.size(), 0.0);
    fit->correlation = Eigen::MatrixXd::Identity(n, n);
  }
  bool all = true;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (!std::isfinite(own[k])) {
      all = false;
      continue;
    }
    fit->sigma[k] = own[k];
    fit->correlation.row(k).setZero();
    fit->correlation.col(k).setZero();
    fit->correlation(k, k) = 1.0;
  }
  fit->has_covariance = fit->has_covariance || all;
  return all;
}

// A selected candidate without a covariance of its own (a closed form, a fit without its holds)
// gets the one propagated through the training runs' final-pose residuals at its point
// (validation/propagated_uncertainty.h), with a closed form's own sigmas where it has them
// (UseOwnSigmas): a written calibration never has sigma: null. False, with the reason on stderr,
// when even that is not possible (nothing may then be written).
bool AddPropagatedUncertainty(const RobotModelInterface& model,
                              const CalibrationCandidate& selected,
                              const std::vector<AlignedRun>& training, SelectedFit* fit) {
  if (fit->has_covariance) return true;
  if (UseOwnSigmas(selected.sigma, fit)) return true;
  const PropagatedUncertainty u =
      PropagateFinalPoseUncertainty(model, selected.parameters, training, fit->held);
  if (!u.ok) {
    std::cerr << "fitcal: no uncertainty for the selected calibration (" << u.message
              << "); nothing written (record more runs, or runs that excite every parameter)\n";
    return false;
  }
  fit->has_covariance = true;
  fit->sigma = u.sigma;
  fit->correlation = CorrelationOf(u.covariance);
  UseOwnSigmas(selected.sigma, fit);
  return true;
}

void PrintParameters(const Robot& robot, const std::vector<double>& p, const SelectedFit& fit) {
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
    } else if (robot.nominal[k] == 0.0) {  // no percentage of nothing (a frame's y of 0)
      std::snprintf(change, sizeof change, "%+.4g m", p[k] - robot.nominal[k]);
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
  if (const std::string frame = GroundTruthFrameLine(robot, fit.held); !frame.empty()) {
    std::printf("  %s\n", frame.c_str());
  }
}

// Nominal (with the effects the robot declares), closed forms, the fit; and when the fit held
// undetermined directions and held-out runs can judge it, the fit without the holds too (on the
// training runs alone it would always win, by fitting what the data cannot tell apart). Under
// --tie/--hold the closed forms stay out: they fit the full model, not the one asked for.
std::vector<CalibrationCandidate> Candidates(const RobotModelInterface& model,
                                             const RunSplit& split, const ModelFitResult& fit,
                                             const std::string& method, bool closed_forms) {
  std::vector<CalibrationCandidate> out = {
      {"nominal", model.robot().nominal, true, model.robot().effects}};
  for (const ClosedFormCalibration& c :
       closed_forms ? model.ClosedForms(split.training) : std::vector<ClosedFormCalibration>{}) {
    out.push_back({c.method, c.parameters, true, {}, c.sigma});
  }
  out.push_back({method, fit.parameters, fit.usable || fit.stopped_early});
  if (!fit.held_directions.empty() && !split.validation.empty()) {
    out.push_back(
        {method + " without holds", fit.unconstrained_parameters, fit.unconstrained_usable});
  }
  return out;
}

bool PrintGate(const std::vector<CalibrationCandidate>& candidates, const GateDecision& gate,
               const std::string& effects_line) {
  std::printf("\nresult gate, CF on %s:\n", gate.judged_on.c_str());
  for (const std::string& line : GateLines(candidates, gate)) std::printf("%s\n", line.c_str());
  if (!effects_line.empty()) std::printf("%s\n", effects_line.c_str());
  if (gate.improves_on_nominal()) return true;
  std::cerr << "fitcal: no calibration beats the nominal robot on the " << gate.judged_on
            << "; nothing written\n";
  return false;
}

// The weights in words: the noise levels the fit estimated, or the sigmas it was given.
std::string WeightsText(const FitCommandOptions& options, const NoiseLevels& levels) {
  if (levels.estimated) return "weights from the data: " + NoiseLevelsText(levels);
  return "sigma_xy " + std::to_string(options.position_sigma_m) + " m, sigma_theta " +
         std::to_string(options.heading_sigma_deg) + " deg";
}

void RecordFitSource(const FitCommandOptions& options, const std::vector<RunLog>& logs,
                     const RunSplit& split, const std::string& method, const std::string& objective,
                     const std::string& termination, const NoiseLevels& levels,
                     io::CalibrationSource* source) {
  io::CalibrationSource& s = *source;
  s.method = method;
  s.objective = objective + " (" + WeightsText(options, levels) + ")";
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

io::CalibrationBlock MakeRecord(const FitCommandOptions& options, const RobotModelInterface& model,
                                const std::vector<RunLog>& logs, const RunSplit& split,
                                const std::vector<CalibrationCandidate>& candidates,
                                const GateDecision& gate, const SelectedFit& selected_fit,
                                const CandidateErrors& errors) {
  const Robot& robot = model.robot();
  const CalibrationCandidate& nominal = candidates[0];
  const CalibrationCandidate& selected = candidates[gate.selected];
  io::CalibrationBlock r;
  RecordFitSource(options, logs, split, selected.name, selected_fit.objective,
                  selected_fit.termination, selected_fit.noise_levels, &r);
  r.cf_training_before = errors(nominal, split.training).cf;
  r.cf_training_after = errors(selected, split.training).cf;
  r.cf_validation_before = errors(nominal, split.validation).cf;
  r.cf_validation_after = errors(selected, split.validation).cf;
  r.selected = selected.name;
  r.selected_on = gate.judged_on;
  for (const HeldParameter& h : robot.held) r.held.push_back(robot.parameters[h.index].name);
  for (int k = 0; k < robot.NumParameters(); ++k) {
    // Held by --hold (fit/parameter_tying.h) beside the model's own holds.
    if (selected_fit.held[k] && !robot.IsHeld(k)) r.held.push_back(robot.parameters[k].name);
  }
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (selected_fit.at_bound[k]) r.at_bound.push_back(robot.parameters[k].name);
  }
  // The uncertainty is the selected fit's (with its effects, when it carries some; the effects'
  // own sigmas are written with them).
  r.has_uncertainty = selected_fit.has_covariance;
  r.sigma = selected_fit.sigma;
  r.correlation = selected_fit.correlation;
  return r;
}

// Exit code 4 with one line when another channel order explains the runs far better.
bool ChannelsLookMiswired(const FitCommandOptions& options, const RobotModelInterface& model,
                          const std::vector<AlignedRun>& training) {
  ChannelOrderOptions order_options;
  order_options.weights.position_sigma_m = options.position_sigma_m;
  order_options.weights.heading_sigma_rad = DegToRad(options.heading_sigma_deg);
  order_options.num_threads = options.threads;
  const ChannelOrderReport order =
      CheckRecordedChannelOrder(training, TracksOf(training), model, order_options);
  if (!order.likely_miswired) return false;
  std::cerr << "fitcal: " << options.logs << ": " << order.message
            << "; nothing written (--skip-wheel-order-check to fit anyway)\n";
  return true;
}

// The header, the CF table, the parameters and the solvers' stop reasons.
void PrintFit(const FitCommandOptions& options, const RobotModelInterface& model,
              const RunSplit& split, const std::vector<CalibrationCandidate>& candidates,
              const GateDecision& gate, const SelectedFit& selected_fit,
              const CandidateErrors& errors, const FitMethod& method,
              const ModelFitMethodOutcome& outcome, const std::optional<TrackFits>& track_fits) {
  const Robot& robot = model.robot();
  const ModelFitResult& fit = outcome.fit;
  std::printf("fitcal %s  %s robot '%s'  data set %s\n", kVersion, robot.model.c_str(),
              robot.name.c_str(), options.logs.c_str());
  const std::string reps = FormatRepetitionList(split.training_repetitions);
  const std::string selection = options.train_trajectories.empty()
                                    ? "repetitions " + reps
                                    : TrainingSelection(options) + "; repetitions " + reps;
  std::printf("runs: %zu training (%s), %zu validation (repetitions %s)\n", split.training.size(),
              selection.c_str(), split.validation.size(),
              FormatRepetitionList(split.validation_repetitions).c_str());
  // A split by trajectory holds families out on purpose; one by repetition may hold none out.
  if (options.train_trajectories.empty()) {
    for (const std::string& note : UnjudgedFamilyNotes(split.training, split.validation)) {
      std::printf("%s\n", note.c_str());
    }
  }
  std::printf("\n");
  const CalibrationCandidate& selected = candidates[gate.selected];
  PrintCfTable(candidates[0], selected, split, errors);
  PrintParameters(robot, selected.parameters, selected_fit);
  for (const effects::EffectValue& e : selected.effects) {
    const effects::EffectInfo& info = effects::Info(e.id);
    for (int k = 0; k < info.num_parameters; ++k) {
      std::printf("  effect %s: %s = %.6g +- %.2g\n", info.name, info.parameter_names[k],
                  e.value[k], e.sigma[k]);
    }
  }
  // Active-set rounds are the Ceres fit's (fit/model_fit.h); NLopt methods have none.
  const std::string rounds =
      fit.active_set_rounds > 0
          ? ", " + std::to_string(fit.active_set_rounds) + " active-set rounds"
          : "";
  std::printf("\nsolver: %s, %s after %d iterations (%d evaluations%s), %.3f s (%s)\n",
              method.description.c_str(), fit.termination.c_str(), fit.iterations,
              outcome.evaluations, rounds.c_str(), fit.solve_time_s, fit.message.c_str());
  if (!fit.global_start.empty()) std::printf("global start: %s\n", fit.global_start.c_str());
  if (track_fits) {
    std::printf(
        "track fits (training tracks): parameters alone %s after %d iterations, with the "
        "effects %s after %d\n",
        track_fits->without_effects.termination.c_str(), track_fits->without_effects.iterations,
        track_fits->with_effects.termination.c_str(), track_fits->with_effects.iterations);
  }
}

std::string EffectNames(const EffectModel& effects) {
  std::string out;
  for (const effects::EffectValue& e : effects) {
    out += std::string(out.empty() ? "" : ", ") + effects::Info(e.id).name;
  }
  return out;
}

// The effects a fit refits: those the robot declares (their values start the fit) and the ones
// --effects names; nullopt after one line on stderr for a name ReadEffectList refuses.
std::optional<EffectModel> EffectsToFit(const FitCommandOptions& options, const Robot& robot) {
  const std::optional<EffectModel> named = ReadEffectList(options.effects, robot, "fit");
  if (!named) return std::nullopt;
  EffectModel out = robot.effects;
  for (const effects::EffectValue& e : *named) {
    const bool declared = std::any_of(out.begin(), out.end(),
                                      [&e](const effects::EffectValue& d) { return d.id == e.id; });
    if (!declared) out.push_back(e);
  }
  return out;
}

// The training runs prepared for the effect fit's track residuals; nullopt after one line on
// stderr when some training run has no ground truth between its ends.
std::optional<std::vector<TrackRun>> TrainingTracks(const FitCommandOptions& options,
                                                    const Robot& robot,
                                                    const std::vector<RunLog>& logs,
                                                    const RunSplit& split) {
  std::unordered_map<std::string, const RunLog*> by_id;
  for (const RunLog& log : logs) by_id[log.id] = &log;
  std::vector<RunLog> training;
  for (const AlignedRun& run : split.training) training.push_back(*by_id.at(run.id));
  try {
    return PrepareTrackRuns(training, WheelChannelMask(robot));
  } catch (const std::invalid_argument& e) {
    std::cerr << "fitcal: fit: " << options.logs
              << ": effects are fitted on the ground truth along each run (a track): " << e.what()
              << "; nothing written\n";
    return std::nullopt;
  }
}

// The model's parameters and `effects` fitted on the training tracks (fit/effect_fit.h),
// from the nominal, as `diagnose` and `generalise --effects` fit them.
EffectFitResult FitEffects(const FitCommandOptions& options, const RobotModelInterface& model,
                           const std::vector<TrackRun>& training, const EffectModel& effects) {
  EffectFitOptions o;
  o.weights = options.Weights();
  o.num_threads = options.threads;
  return FitEffectModel(training, model, model.robot().nominal, effects, o);
}

// The candidate without effects with the lowest CF on the runs that judged (-1: none usable).
int BestWithoutEffects(const std::vector<CalibrationCandidate>& candidates,
                       const GateDecision& gate) {
  int best = -1;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (!candidates[i].effects.empty() || !std::isfinite(gate.cf[i])) continue;
    if (best < 0 || gate.cf[i] < gate.cf[best]) best = static_cast<int>(i);
  }
  return best;
}

// An effect earns its place as a calibration earns it against the nominal: the gate's choice,
// when it carries effects, must have lower per-run CFs than the same track fit without them
// (like for like: the track objective alone must not be credited to the effects), by the
// one-sided paired test on the log ratios (stats::PairedLogRatioTest, p < kEffectAlpha) on the
// runs that judged; otherwise the best candidate without effects is selected. The line that says
// which, or empty.
constexpr double kEffectAlpha = 0.01;

std::string RequireEffectsToEarnTheirPlace(const std::vector<CalibrationCandidate>& candidates,
                                           const RunSplit& split, const CandidateErrors& errors,
                                           const TrackFits& track_fits, GateDecision* gate) {
  const CalibrationCandidate& chosen = candidates[gate->selected];
  if (chosen.effects.empty()) return "";
  const CalibrationCandidate& without = candidates[track_fits.without_index];
  const std::vector<AlignedRun>& runs =
      gate->judged_on_held_out ? split.validation : split.training;
  const stats::PairedTest test =
      stats::PairedLogRatioTest(errors(without, runs).per_run_cf, errors(chosen, runs).per_run_cf);
  char line[400];
  if (test.p < kEffectAlpha) {
    std::snprintf(line, sizeof line,
                  "effects: '%s' beats '%s' run by run (paired log-ratio t = %.2f, p = %.2g < %g)",
                  chosen.name.c_str(), without.name.c_str(), test.t, test.p, kEffectAlpha);
    return line;
  }
  // The nominal carries effects only when the robot declares them; then some fit must stand in.
  const int best = std::max(0, BestWithoutEffects(candidates, *gate));
  std::snprintf(line, sizeof line,
                "effects: '%s' is not significantly better than '%s' run by run (paired "
                "log-ratio t = %.2f, p = %.2g >= %g): '%s' is selected",
                chosen.name.c_str(), without.name.c_str(), test.t, test.p, kEffectAlpha,
                candidates[best].name.c_str());
  gate->selected = best;
  return line;
}

// When the selected calibration carries effects: what an odometry of the parameters alone (a
// ros2_controllers controller) gets from it, and from the best candidate without effects.
void WarnOfEffects(const std::vector<CalibrationCandidate>& candidates, const GateDecision& gate,
                   const RunSplit& split, const CandidateErrors& errors) {
  const CalibrationCandidate& selected = candidates[gate.selected];
  if (selected.effects.empty()) return;
  const std::vector<AlignedRun>& runs = gate.judged_on_held_out ? split.validation : split.training;
  const double alone = errors({selected.name, selected.parameters, true, {}}, runs).cf;
  const int best = BestWithoutEffects(candidates, gate);
  std::cerr << "fitcal: note: the calibration carries effects (" << EffectNames(selected.effects)
            << ") that an odometry of the parameters alone (a ros2_controllers controller) does "
               "not apply: there its parameters give CF "
            << alone << " on the " << gate.judged_on;
  if (best >= 0) {
    std::cerr << ", the best calibration without effects ('" << candidates[best].name << "') "
              << gate.cf[best];
  }
  std::cerr << "; for such a controller, fit without effects (no --effects, no effects: in the "
               "robot YAML)\n";
}

// The training runs' tracks for --residuals track/both, and auto resolved (settings->track points
// into *data); false after one line on stderr when the method cannot fit them.
bool PrepareTrackResiduals(const FitCommandOptions& options, const RunSplit& split,
                           FitMethodSettings* settings,
                           std::optional<TrackFitData>* data) {
  const std::vector<const GroundTruthTrack*> tracks = TracksOf(split.training);
  ResolveAutoResiduals(split.training, tracks, options.method, settings);
  if (settings->residuals == ResidualKind::kFinalPose) return true;
  if (options.method != "ceres" && options.method != "ceres-dogleg") {
    std::cerr << "fitcal: --residuals " << ToString(settings->residuals)
              << " needs a Ceres method (--method ceres or ceres-dogleg); " << options.method
              << " fits final poses only\n";
    return false;
  }
  TrackResidualOptions track_options;
  track_options.heading = settings->track_heading;
  data->emplace(MakeTrackFitData(split.training, tracks, settings->clock_grouping, track_options));
  settings->track = &**data;
  return true;
}

// The fit's residual degrees of freedom (validation/residual_dof.h), counted for the residuals
// it will minimise: three final-pose residuals per training run, three per track checkpoint
// (plus the final poses with `both`), and the clock offsets as parameters when estimated. A
// single long free run thus calibrates on its track, where its final pose alone could not.
std::string DegreesOfFreedomRefusal(const RunSplit& split, const FitMethodSettings& settings,
                                    const std::optional<TrackFitData>& track,
                                    std::size_t num_parameters) {
  if (!track) return FinalPoseDofRefusal(split.training.size(), num_parameters);
  std::size_t checkpoints = 0;
  for (const TrackCheckpoints& run : track->runs) checkpoints += run.segments.size();
  std::size_t residuals = 3 * checkpoints;
  if (settings.residuals == ResidualKind::kBoth) residuals += 3 * split.training.size();
  if (track->estimate_clock_offsets) num_parameters += track->clock_groups.size();
  const std::size_t runs = std::max<std::size_t>(1, split.training.size());
  return ResidualDofRefusal(residuals, num_parameters, split.training.size(), "track",
                            residuals / runs);
}

// The clock offsets the track fit estimated, into the calibrated YAML's `clock_offsets:` (the
// report and diagnose apply them to runs of the same groups).
void RecordClockOffsets(const ModelFitResult& fit, const TrackFitData& track,
                        ClockGrouping grouping, io::CalibrationBlock* record) {
  if (!track.estimate_clock_offsets) return;
  record->clock_offset_grouping = ToString(grouping);
  for (std::size_t g = 0; g < track.clock_groups.size() && g < fit.clock_offsets_s.size(); ++g) {
    const double sigma = g < fit.clock_offset_sigma_s.size() ? fit.clock_offset_sigma_s[g] : 0.0;
    record->clock_offsets.push_back({track.clock_groups[g], fit.clock_offsets_s[g], sigma});
  }
}

// The clock offsets the track fit estimated, with their sigmas: every group up to a dozen, their
// range beyond.
void PrintClockOffsets(const ModelFitResult& fit, const TrackFitData& track) {
  if (!track.estimate_clock_offsets || track.clock_groups.empty()) return;
  const std::size_t n = track.clock_groups.size();
  const auto sigma = [&](std::size_t g) {
    return g < fit.clock_offset_sigma_s.size() ? fit.clock_offset_sigma_s[g] : 0.0;
  };
  std::printf("clock offsets (ground truth at encoder time + dt, |dt| <= %.2g s), %zu %s:\n",
              track.options.max_clock_offset_s, n, n == 1 ? "group" : "groups");
  constexpr std::size_t kMaxListed = 12;
  // An offset on its bound is where the fit was stopped, not a measured lag: said, with the
  // groups, so that it is not read as one.
  const double bound = track.options.max_clock_offset_s;
  std::string on_bound;
  std::size_t num_on_bound = 0;
  for (std::size_t g = 0; g < n; ++g) {
    if (std::abs(fit.clock_offsets_s[g]) < bound * (1.0 - 1e-3)) continue;
    ++num_on_bound;
    if (num_on_bound <= 3) on_bound += (on_bound.empty() ? "" : ", ") + track.clock_groups[g];
  }
  const auto warn_on_bound = [&] {
    if (num_on_bound == 0) return;
    std::printf("warning: %zu clock offset%s rest%s on the +-%.2g s bound (%s%s): not a measured "
                "lag; the clocks differ by more, or the offset absorbs a mismatch of the runs "
                "(--clock-offsets none, or check the ground truth's time stamps)\n",
                num_on_bound, num_on_bound == 1 ? "" : "s", num_on_bound == 1 ? "s" : "", bound,
                on_bound.c_str(), num_on_bound > 3 ? ", ..." : "");
  };
  if (n <= kMaxListed) {
    for (std::size_t g = 0; g < n; ++g) {
      std::printf("  %-36s %+8.3f s +- %.3f\n", track.clock_groups[g].c_str(),
                  fit.clock_offsets_s[g], sigma(g));
    }
    warn_on_bound();
    return;
  }
  std::vector<double> sorted(fit.clock_offsets_s.begin(), fit.clock_offsets_s.begin() + n);
  std::sort(sorted.begin(), sorted.end());
  double mean_sigma = 0.0;
  for (std::size_t g = 0; g < n; ++g) mean_sigma += sigma(g) / n;
  std::printf("  median %+.3f s, range [%+.3f, %+.3f] s, mean sigma %.3f s\n", sorted[n / 2],
              sorted.front(), sorted.back(), mean_sigma);
  warn_on_bound();
}

// Drift per 1, 2, 5 m and ATE RMSE (tools/everyday_driving_table.h) of the nominal and the
// selected calibration on the held-out runs (the training runs when none is held out).
void PrintEverydayDriving(const RobotModelInterface& model, const RunSplit& split,
                          const CalibrationCandidate& nominal,
                          const CalibrationCandidate& selected, int threads) {
  const bool held_out = !split.validation.empty();
  const std::vector<AlignedRun>& runs = held_out ? split.validation : split.training;
  PrintEverydayDrivingTable(
      model, runs, TracksOf(runs),
      held_out ? "everyday driving, validation" : "everyday driving, training",
      {&nominal.parameters, &nominal.effects}, {&selected.parameters, &selected.effects}, threads);
}

// How the choices by transfer and the held-out halves score a fit: the everyday-driving
// measures (Eq. 14 CF, drift per length, ATE) of parameters `p` on runs, each against its track.
ScoreOnRuns EverydayDrivingScore(const RobotModelInterface& model, int threads) {
  return [&model, threads](const std::vector<double>& p, const std::vector<AlignedRun>& runs) {
    return EvaluateEverydayDriving(model, p, {}, runs, TracksOf(runs), EverydayDriftLengths(),
                                   threads);
  };
}

// The fits of the folds the choices by transfer make (residual kind, then track objective), each
// made once: the track with the default objective on a fold is a candidate of both.
class FoldFits {
 public:
  // `s` fitted on `training` from `start` (the fit of all the training runs), its weights seeded
  // by that fit's noise levels when it estimated them; nullopt when not usable.
  std::optional<std::vector<double>> Fit(const FitCommandOptions& options, const FitMethod& method,
                                         const RobotModelInterface& model, FitMethodSettings s,
                                         const std::vector<AlignedRun>& training) {
    std::string key = std::string(ToString(s.residuals)) + (s.estimate_weights ? " est " : " fix ") +
                      ToString(s.track_heading);
    for (const AlignedRun& run : training) key += " " + run.id;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (const auto found = done_.find(key); found != done_.end()) return found->second;
    }
    s.residuals_auto = false;
    s.track = nullptr;
    s.start = start;
    if (s.estimate_weights && seed_levels.estimated) {
      s.track_weights = WeightsFromNoiseLevels(seed_levels).track;
    }
    RunSplit part;
    part.training = training;
    std::optional<TrackFitData> data;
    std::optional<std::vector<double>> out;
    if (PrepareTrackResiduals(options, part, &s, &data)) {
      const ModelFitResult fit = method.run_model(training, model, s).fit;
      if (fit.usable || fit.stopped_early) out = fit.parameters;
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    done_[key] = out;
    return out;
  }

  std::vector<double> start;  // empty: the nominal
  NoiseLevels seed_levels;

 private:
  std::mutex mutex_;
  std::map<std::string, std::optional<std::vector<double>>> done_;
};

// The fit of all the training runs with `settings` into *full; the folds' fits start from it.
void FitAllTrainingRuns(const FitMethod& method, const RobotModelInterface& model,
                        const RunSplit& split, const FitMethodSettings& settings,
                        std::optional<ModelFitMethodOutcome>* full, FoldFits* fold_fits) {
  full->emplace(method.run_model(split.training, model, settings));
  const ModelFitResult& whole = (*full)->fit;
  if (whole.usable || whole.stopped_early) fold_fits->start = whole.parameters;
  fold_fits->seed_levels = whole.noise_levels;
}

// --residuals auto proposing the track: the track and the final pose are fitted and judged on
// kinds of run they were not fitted on (validation/residual_kind_transfer.h); the final pose
// replaces the track when that judgement says so (settings and *track_data follow). The folds'
// fits start from the track fit of all the training runs (`full`, the fit the command writes
// when the track stays), so each ends in a few steps, and run in parallel. The lines for the
// terminal; none when nothing could be judged.
std::vector<std::string> ChooseResidualsByTransfer(const FitCommandOptions& options,
                                                   const FitMethod& method,
                                                   const RobotModelInterface& model,
                                                   const RunSplit& split,
                                                   FitMethodSettings* settings,
                                                   std::optional<TrackFitData>* track_data,
                                                   std::optional<ModelFitMethodOutcome>* full,
                                                   FoldFits* fold_fits) {
  if (!settings->residuals_auto || settings->residuals != ResidualKind::kTrack) return {};
  FitAllTrainingRuns(method, model, split, *settings, full, fold_fits);
  const FitByKind fit_on = [&](ResidualKind kind, const std::vector<AlignedRun>& training) {
    FitMethodSettings s = *settings;
    s.residuals = kind;
    return fold_fits->Fit(options, method, model, s, training);
  };
  const ScoreOnRuns score = EverydayDrivingScore(model, options.threads);
  const ResidualKindJudgement judgement = JudgeResidualKindsByTransfer(
      ResidualKind::kTrack, ResidualKind::kFinalPose, split, fit_on, score);
  if (judgement.chosen != settings->residuals) {
    settings->residuals = judgement.chosen;
    settings->track = nullptr;
    track_data->reset();
    full->reset();
  }
  return ResidualKindJudgementLines(judgement);
}

// The track objectives --weights auto / --track-heading auto allow, the default first (weights
// fixed unless --weights estimated, heading from the start unless given).
std::vector<TrackObjective> TrackObjectiveCandidates(const FitMethodSettings& settings) {
  const std::vector<bool> weights =
      settings.weights_auto ? std::vector<bool>{false, true}
                            : std::vector<bool>{settings.estimate_weights};
  const std::vector<TrackHeading> headings =
      settings.track_heading_auto
          ? std::vector<TrackHeading>{TrackHeading::kFromStart, TrackHeading::kIncrements}
          : std::vector<TrackHeading>{settings.track_heading};
  std::vector<TrackObjective> out;
  for (TrackHeading heading : headings) {
    for (bool estimate : weights) out.push_back({estimate, heading});
  }
  return out;
}

// --weights auto / --track-heading auto on track residuals: the candidates fitted and judged by
// transfer (validation/track_objective_transfer.h), each fold's fit started from the fit of all
// the training runs when the residual choice made one; settings, *track_data and *full follow the
// choice. The lines for the terminal, and in *note what the calibration's objective records.
std::vector<std::string> ChooseTrackObjectiveByTransfer(
    const FitCommandOptions& options, const FitMethod& method, const RobotModelInterface& model,
    const RunSplit& split, FitMethodSettings* settings,
    std::optional<TrackFitData>* track_data, std::optional<ModelFitMethodOutcome>* full,
    FoldFits* fold_fits, std::string* note) {
  if (!settings->weights_auto && !settings->track_heading_auto) return {};
  if (settings->residuals == ResidualKind::kFinalPose) return {};
  // The default candidate's fit of all the runs (unless the residual choice made it): the folds'
  // start, and the fit written when the default is kept.
  if (!*full) FitAllTrainingRuns(method, model, split, *settings, full, fold_fits);
  const FitByTrackObjective fit_on = [&](const TrackObjective& objective,
                                         const std::vector<AlignedRun>& training) {
    FitMethodSettings s = *settings;
    s.estimate_weights = objective.estimate_weights;
    s.track_heading = objective.heading;
    return fold_fits->Fit(options, method, model, s, training);
  };
  const ScoreOnRuns score = EverydayDrivingScore(model, options.threads);
  const TrackObjectiveJudgement judgement = JudgeTrackObjectivesByTransfer(
      TrackObjectiveCandidates(*settings), split, fit_on, score);
  *note = TrackObjectiveChoiceText(judgement);
  if (judgement.chosen != 0) {
    const TrackObjective& chosen = judgement.candidates[judgement.chosen];
    settings->estimate_weights = chosen.estimate_weights;
    settings->track_heading = chosen.heading;
    settings->track = nullptr;
    track_data->reset();
    full->reset();
    if (!PrepareTrackResiduals(options, split, settings, track_data)) return {};
  }
  return TrackObjectiveJudgementLines(judgement);
}

// A calibration better than the nominal on the held-out runs as a whole may still be worse on
// one kind of run, or in drift or ATE, beyond the runs' own scatter (validation/never_worse.h);
// it is then not written. True after one line per such measure on stderr.
bool WorseThanNominalBeyondNoise(const RobotModelInterface& model,
                                 const std::vector<CalibrationCandidate>& candidates,
                                 const GateDecision& gate, const RunSplit& split, int threads) {
  if (!gate.judged_on_held_out || gate.selected == 0) return false;
  const std::vector<NeverWorseJudgement> judged =
      JudgeCalibrationNeverWorse(model, candidates[0], candidates[gate.selected], split.validation,
                                 TracksOf(split.validation), threads);
  const NeverWorseSaid said = SayNeverWorse(candidates[gate.selected].name, judged);
  for (const std::string& line : said.warnings) std::printf("warning: %s\n", line.c_str());
  for (const std::string& line : said.refusals) std::cerr << "fitcal: " << line << "; nothing written\n";
  return !said.refusals.empty();
}

// With nothing held out, the two-fold judgement of validation/held_out_halves.h, each fold fitted
// by the command's method with the whole data's settings and scored on the final pose (Eq. 14).
HalvesJudgement JudgeMethodOnHeldOutHalves(const FitCommandOptions& options,
                                           const FitMethod& method,
                                           const FitMethodSettings& settings,
                                           const RobotModelInterface& model,
                                           const RunSplit& split) {
  const FitOnFold fit_on = [&](const HalvesFold& fold) -> std::optional<std::vector<double>> {
    FitMethodSettings fold_settings = settings;
    fold_settings.residuals_auto = false;  // the whole data's choice holds for its halves
    std::optional<TrackFitData> track_data;
    if (!PrepareTrackResiduals(options, fold.split, &fold_settings, &track_data)) {
      return std::nullopt;
    }
    const ModelFitResult fit = method.run_model(fold.split.training, model, fold_settings).fit;
    if (!(fit.usable || fit.stopped_early)) return std::nullopt;
    return fit.parameters;
  };
  const ScoreOnRuns on_runs = EverydayDrivingScore(model, options.threads);
  const MetricsOnFold score = [&](const std::vector<double>& p, const HalvesFold& fold) {
    return on_runs(p, fold.split.validation);
  };
  return fitcal::JudgeOnHeldOutHalves(split, settings.residuals, options.time_blocks,
                                      model.robot().nominal, fit_on, score);
}

// Prints the judgement; false (exit 5, nothing written) when the fits of one half do not beat the
// nominal on the other, or are worse in some measure beyond the noise.
bool ReportHalves(const HalvesJudgement& j) {
  if (!j.judged) return true;
  std::printf("no held-out runs: judged on %s; the calibration written is fitted on all of them\n",
              HalvesDescription(j).c_str());
  if (j.Beats()) return true;
  const std::string half = j.by_time ? "the run's time" : "the training runs";
  for (const HalvesGroup& g : j.groups) {
    if (g.Beats()) continue;
    const std::string which =
        g.block_count > 0 ? " (" + std::to_string(g.block_count) + " blocks)" : "";
    if (!(g.calibrated_cf < g.nominal_cf)) {
      std::cerr << "fitcal: fitted on half of " << half << which
                << ", the calibration does not beat the nominal on the other half (CF "
                << g.nominal_cf << " -> " << g.calibrated_cf << ")\n";
    }
    for (const std::string& line : NeverWorseRefusals("the fit of one half" + which, g.never_worse)) {
      std::cerr << "fitcal: " << line << "\n";
    }
  }
  std::cerr << "fitcal: the runs do not determine the parameters; record more driving; nothing "
               "written\n";
  return false;
}

// What the fit itself cannot notice, said after it: training runs whose final-pose error under
// the fit is far beyond the others' (diagnosis/degenerate_data.h: gross slip, a ground truth of
// another run), and parameters that stopped on their bounds.
void PrintFitWarnings(const FitCommandOptions& options, const RobotModelInterface& model,
                      const RunSplit& split, const ModelFitResult& fit) {
  if (fit.usable || fit.stopped_early) {
    std::vector<std::string> ids;
    for (const AlignedRun& run : split.training) ids.push_back(run.id);
    const FinalPoseErrors errors =
        EvaluateFinalPoseErrors(model, fit.parameters, split.training, options.threads);
    for (const OutlierRun& o : FindOutlierRuns(ids, errors.per_run_cf)) {
      std::printf(
          "warning: run %s: final-pose error %.1fx the median run's (gross wheel slip or a "
          "ground truth of another run?); a robust loss limits its pull\n",
          o.id.c_str(), o.error_ratio);
    }
  }
  if (std::find(fit.at_bound.begin(), fit.at_bound.end(), true) != fit.at_bound.end()) {
    std::printf(
        "warning: a parameter stopped on its bound; the model may be absorbing an effect it "
        "does not contain, or the bounds are too tight\n");
  }
}

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

// Before fitting, as a fit would not notice them: runs that stand still and rates in the wrong
// unit (exit 1), miswired channels (exit 4), data that cannot determine the parameters
// (warnings). 0 to go on.
int CheckBeforeFitting(const FitCommandOptions& options, const RobotModelInterface& model,
                       const RunSplit& split, const std::vector<RunLog>& logs) {
  std::vector<RunLog> training_logs;
  for (const AlignedRun& run : split.training) {
    for (const RunLog& log : logs) {
      if (log.id == run.id) training_logs.push_back(log);
    }
  }
  if (const std::string still = StillRunsRefusal(training_logs); !still.empty()) {
    std::cerr << "fitcal: " << options.logs << ": " << still << "\n";
    return 1;
  }
  if (const RateUnitsFinding units = CheckModelRateUnits(model, logs); units.suspicious) {
    std::cerr << "fitcal: " << options.logs << ": " << units.message << "\n";
    return 1;
  }
  if (!options.skip_wheel_order_check &&
      ChannelsLookMiswired(options, model, split.training)) {
    return 4;
  }
  for (const std::string& problem : FindDegenerateData(split.training, model.robot())) {
    std::printf("warning: %s\n", problem.c_str());
  }
  return 0;
}

// The track fits without and with the effects to fit, appended to the gate's candidates.
TrackFits AddTrackFitCandidates(const FitCommandOptions& options, const RobotModelInterface& model,
                                const std::vector<TrackRun>& training_tracks,
                                const EffectModel& effects_to_fit,
                                std::vector<CalibrationCandidate>* candidates) {
  TrackFits t;
  t.without_effects = FitEffects(options, model, training_tracks, {});
  t.with_effects = FitEffects(options, model, training_tracks, effects_to_fit);
  t.without_index = static_cast<int>(candidates->size());
  candidates->push_back({"track fit", t.without_effects.parameters, t.without_effects.usable});
  t.with_index = static_cast<int>(candidates->size());
  candidates->push_back({"track fit + " + EffectNames(effects_to_fit), t.with_effects.parameters,
                         t.with_effects.usable, t.with_effects.effects});
  return t;
}

// Each direction held at the nominal, and what to drive to determine it (fit/motion_advice.h).
void PrintHeldDirections(const RobotModelInterface& model, const ModelFitResult& fit,
                         const ResidualWeights& weights) {
  for (const UndeterminedDirection& d : fit.held_directions) {
    PrintHeldAtNominal(d.description);
    const std::vector<MotionThatDetermines> motions =
        MotionsThatDetermine(d, model, fit.parameters, weights);
    std::printf("  %s\n", MotionAdviceLine(motions).c_str());
  }
}

void WriteCalibration(const FitCommandOptions& options, const RobotModelInterface& model,
                      const CalibrationCandidate& selected, const io::CalibrationBlock& record) {
  io::StopHereForTests("fitted");
  io::WriteFileAtomically(options.out,
                          model.RobotYaml(selected.parameters, selected.effects,
                                          io::CalibrationBlockYaml(record, model.robot())));
  std::printf("wrote %s\n", options.out.c_str());
}

std::size_t NumFreeWithTying(const RobotModelInterface& model, const ParameterTying& tying) {
  if (tying.empty()) return model.robot().NumFree();
  return TiedModel(model, tying).robot().NumFree();
}

// The method, its settings and the effects to fit, checked before anything is loaded.
struct FitSetup {
  const FitMethod* method = nullptr;
  FitMethodSettings settings;
  EffectModel effects_to_fit;
};

// A flag the fit asked for would not use: "" or the refusal's one line (exit 2), so that nothing
// the user set is dropped without a word. Defaults are those of SolverOptions (a flag given at its
// default changes nothing either way).
std::string FlagThatDoesNotApply(const FitCommandOptions& o) {
  const SolverOptions defaults;
  const bool ceres = o.method == "ceres" || o.method == "ceres-dogleg";
  const bool loss = o.loss != defaults.loss;
  if (!ceres && (loss || o.loss_scale != defaults.loss_scale)) {
    return "--loss and --loss-scale shape the Ceres methods' final-pose residuals; --method " +
           o.method + " does not use them";
  }
  if (!ceres && o.max_iterations != defaults.max_iterations) {
    return "--max-iterations bounds the Ceres methods; --method " + o.method +
           " has --max-evaluations";
  }
  if (ceres && (o.seed != defaults.seed || o.max_evaluations != defaults.max_evaluations ||
                o.polish)) {
    return "--seed, --max-evaluations and --polish apply to the NLopt methods; --method " +
           o.method + " does not use them";
  }
  if (!loss && o.loss_scale != defaults.loss_scale) {
    return "--loss-scale without --loss (huber or cauchy) has no loss to scale";
  }
  if (o.residuals == "final-pose" && o.clock_offsets != defaults.clock_offsets) {
    return "--clock-offsets " + o.clock_offsets +
           " is estimated on track residuals; --residuals final-pose compares final poses, "
           "where no clock offset is estimated (--residuals track or both)";
  }
  if (o.residuals == "track" && (loss || !o.objective.empty())) {
    return std::string(loss ? "--loss" : "--objective") +
           " shapes final-pose residuals; the track residual has its own fixed Huber loss "
           "(--residuals both fits final poses too)";
  }
  return "";
}

// What --residuals auto's choice leaves unused of the flags given, said beside the residuals:
// the clock offsets belong to the track, the loss and the objective to the final poses.
std::vector<std::string> FlagsTheChoiceLeavesUnused(const FitCommandOptions& o,
                                                    const FitMethodSettings& settings) {
  if (!settings.residuals_auto) return {};
  const SolverOptions defaults;
  std::vector<std::string> notes;
  if (settings.residuals == ResidualKind::kFinalPose && o.clock_offsets != defaults.clock_offsets) {
    notes.push_back("note: --clock-offsets " + o.clock_offsets +
                    " not applied: final-pose residuals were chosen, on which no clock offset "
                    "is estimated (--residuals track estimates it on dense ground truth)");
  }
  if (settings.residuals == ResidualKind::kTrack && o.loss != defaults.loss) {
    notes.push_back("note: --loss " + o.loss +
                    " not applied: track residuals were chosen, which carry their own fixed "
                    "Huber loss (--residuals final-pose or both use --loss)");
  }
  if (settings.residuals == ResidualKind::kTrack && !o.objective.empty()) {
    notes.push_back("note: --objective " + o.objective +
                    " not applied: track residuals were chosen (it shapes final-pose residuals)");
  }
  return notes;
}

// Fills `setup`; else one line on stderr and the exit code (2 for a flag, the overwrite refusal's
// for an output fitcal did not write).
int SetUpFit(const FitCommandOptions& options, const Robot& robot, FitSetup* setup) {
  // Validated by RunFitCommand: a known method, settings in range.
  setup->method = FindFitMethod(options.method);
  if (const std::string unused = FlagThatDoesNotApply(options); !unused.empty()) {
    std::cerr << "fitcal: " << unused << "\n";
    return 2;
  }
  std::string error;
  if (setup->method == nullptr ||
      !MakeFitMethodSettings(options, options.threads, &setup->settings, &error)) {
    std::cerr << "fitcal: "
              << (setup->method == nullptr ? "unknown --method " + options.method : error) << "\n";
    return 2;
  }
  if (const std::string refusal = ReadTying(options, robot, &setup->settings.tying);
      !refusal.empty()) {
    return Refuse(refusal);
  }
  const std::optional<EffectModel> effects_to_fit = EffectsToFit(options, robot);
  if (!effects_to_fit) return 2;
  if (!setup->settings.tying.empty() && !effects_to_fit->empty()) {
    return Refuse("--tie and --hold apply to the parameters' fit, not to the effect fit (--effects "
                  "or effects the robot YAML declares), which moves every parameter");
  }
  setup->effects_to_fit = *effects_to_fit;
  if (!options.no_output && !options.force) {
    const std::string refusal = OverwriteRefusal(options.out, robot.name);
    if (!refusal.empty()) return Refuse(refusal);
  }
  return 0;
}

// The residuals fitted, how they were chosen, and the clock offsets fitted with them.
void PrintResiduals(const FitMethodSettings& settings, bool residuals_auto,
                    const std::vector<std::string>& residual_choice, const ModelFitResult& fit,
                    const std::optional<TrackFitData>& track_data) {
  std::printf("residuals: %s%s\n", ToString(settings.residuals),
              residuals_auto ? " (--residuals auto)" : "");
  for (const std::string& line : residual_choice) std::printf("%s\n", line.c_str());
  if (fit.noise_levels.estimated) {
    std::printf("weights from the data (variance components at the solution; "
                "--position-sigma-m/--heading-sigma-deg override): %s\n",
                NoiseLevelsText(fit.noise_levels).c_str());
  }
  if (track_data) PrintClockOffsets(fit, *track_data);
}

// The counter glitches the loader dropped (io/log_files.h), each named above with its line.
void PrintEncoderGlitches(const std::vector<RunLog>& runs) {
  int glitches = 0, runs_with = 0;
  for (const RunLog& run : runs) {
    glitches += run.encoders.dropped_glitches;
    runs_with += run.encoders.dropped_glitches > 0;
  }
  if (glitches == 0) return;
  std::printf("encoder glitches: %d interval%s in %d run%s dropped from the fit (each named with "
              "its file:line in the warnings)\n",
              glitches, glitches == 1 ? "" : "s", runs_with, runs_with == 1 ? "" : "s");
}

// What the fit could not determine and what looks wrong with it.
void PrintUncertaintyAndWarnings(const FitCommandOptions& options,
                                 const RobotModelInterface& model, const RunSplit& split,
                                 const ModelFitResult& fit, const ResidualWeights& weights) {
  if (!fit.has_covariance) std::printf("uncertainty: %s\n", fit.covariance_message.c_str());
  PrintHeldDirections(model, fit, weights);
  PrintFitWarnings(options, model, split, fit);
}

}  // namespace

int RunModelFitCommand(const FitCommandOptions& options, const io::DatasetIndex& index,
                       const RobotModelPtr& model) {
  const auto t_total = std::chrono::steady_clock::now();
  const Robot& robot = model->robot();
  FitSetup setup;
  if (const int refused = SetUpFit(options, robot, &setup); refused != 0) return refused;
  const FitMethod* method = setup.method;
  FitMethodSettings& settings = setup.settings;
  const std::optional<EffectModel> effects_to_fit = setup.effects_to_fit;
  const io::Dataset dataset = LoadRuns(options, index, &robot);
  io::StopHereForTests("loaded");
  RunSplit split =
      SplitForFit(AlignRuns(dataset.runs), options.train_reps, options.train_trajectories);
  // The runs by id, with the time blocks' when a single long run is cut (ValidateOnTimeBlocks).
  std::vector<RunLog> logs = dataset.runs;
  const bool residuals_auto = settings.residuals_auto;
  const double load_s = Seconds(t_total);
  if (split.training.empty()) {
    std::cerr << "fitcal: no run of " << options.logs << " is a training run ("
              << TrainingSelection(options) << ")\n";
    return 2;
  }
  if (const int refused = CheckBeforeFitting(options, *model, split, logs); refused != 0) {
    return refused;
  }
  std::optional<std::vector<TrackRun>> training_tracks;
  if (!effects_to_fit->empty()) {
    training_tracks = TrainingTracks(options, robot, logs, split);
    if (!training_tracks) return 2;
  }
  std::optional<TrackFitData> track_data;
  if (!PrepareTrackResiduals(options, split, &settings, &track_data)) return 2;
  // The fit of all the training runs when the choice by transfer made it (and kept its kind).
  std::optional<ModelFitMethodOutcome> chosen_fit;
  FoldFits fold_fits;
  const std::vector<std::string> residual_choice =
      effects_to_fit->empty()
          ? ChooseResidualsByTransfer(options, *method, *model, split, &settings,
                                      &track_data, &chosen_fit, &fold_fits)
          : std::vector<std::string>{};
  std::vector<std::string> residual_lines = residual_choice;
  std::string objective_note;
  if (effects_to_fit->empty()) {
    for (const std::string& line :
         ChooseTrackObjectiveByTransfer(options, *method, *model, split, &settings,
                                        &track_data, &chosen_fit, &fold_fits,
                                        &objective_note)) {
      residual_lines.push_back(line);
    }
  }
  for (const std::string& note : FlagsTheChoiceLeavesUnused(options, settings)) {
    residual_lines.push_back(note);
  }
  const HalvesJudgement halves =
      JudgeMethodOnHeldOutHalves(options, *method, settings, *model, split);
  if (const std::string refusal = DegreesOfFreedomRefusal(
          split, settings, track_data,
          NumFreeWithTying(*model, settings.tying) + (effects_to_fit ? effects_to_fit->size() : 0));
      !refusal.empty()) {
    std::cerr << "fitcal: " << options.logs << ": " << refusal << "\n";
    return 1;
  }
  const ModelFitMethodOutcome outcome =
      chosen_fit ? std::move(*chosen_fit) : method->run_model(split.training, *model, settings);
  const ModelFitResult& fit = outcome.fit;
  std::vector<CalibrationCandidate> candidates =
      Candidates(*model, split, fit, options.method, settings.tying.empty());
  const std::optional<TrackFits> track_fits =
      training_tracks ? std::optional<TrackFits>(AddTrackFitCandidates(
                            options, *model, *training_tracks, *effects_to_fit, &candidates))
                      : std::nullopt;
  const CandidateErrors errors(*model, options.threads);
  GateDecision gate = SelectCalibration(*model, candidates, split.training, split.validation,
                                        options.threads, errors.Cf());
  const std::string effects_line =
      track_fits ? RequireEffectsToEarnTheirPlace(candidates, split, errors, *track_fits, &gate)
                 : "";
  const CalibrationCandidate& selected = candidates[gate.selected];
  SelectedFit selected_fit = DescribeSelected(robot, candidates, gate.selected, options.method,
                                              outcome.objective + objective_note, fit,
                                              track_fits);
  if (gate.selected != 0 && !options.no_output &&
      !AddPropagatedUncertainty(*model, selected, split.training, &selected_fit)) {
    return 1;
  }

  PrintFit(options, *model, split, candidates, gate, selected_fit, errors, *method, outcome,
           track_fits);
  PrintTying(settings.tying);
  PrintResiduals(settings, residuals_auto, residual_lines, fit, track_data);
  PrintEncoderGlitches(dataset.runs);
  PrintEverydayDriving(*model, split, candidates[0], selected, options.threads);
  PrintUncertaintyAndWarnings(options, *model, split, fit, settings.weights);
  if (halves.judged) {  // the gate's table is on the training runs; the halves judge (below)
    gate.judged_on = "training runs (" + std::to_string(split.training.size()) +
                     "; no held-out runs: judged on held-out " +
                     (halves.by_time ? "time blocks" : "halves") + ", below)";
  }
  if (!PrintGate(candidates, gate, effects_line)) return 5;
  if (!ReportHalves(halves)) return 5;
  if (halves.judged) gate.judged_on = HalvesDescription(halves);
  if (WorseThanNominalBeyondNoise(*model, candidates, gate, split, options.threads)) return 5;
  if (const std::string refusal =
          AtBoundRefusal(robot, selected.name, selected.parameters, selected_fit.at_bound);
      !refusal.empty() && gate.selected != 0) {
    if (!options.bounds_widened) {
      std::cerr << "fitcal: " << refusal << "; nothing written\n";
      return 5;
    }
    std::printf("warning: %s; written as --bounds-widened asks\n", refusal.c_str());
  }
  WarnOfEffects(candidates, gate, split, errors);
  if (!options.no_output) {
    io::CalibrationBlock record =
        MakeRecord(options, *model, logs, split, candidates, gate, selected_fit, errors);
    if (track_data && selected.name == options.method) {
      RecordClockOffsets(fit, *track_data, settings.clock_grouping, &record);
    }
    WriteCalibration(options, *model, selected, record);
  }
  std::printf("time: load %.3f s, total %.3f s\n", load_s, Seconds(t_total));
  return StoppedEarlyExit(fit.stopped_early && candidates[gate.selected].name == options.method,
                          fit.termination);
}

}  // namespace fitcal::tools
