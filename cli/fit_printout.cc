#include "cli/fit_printout.h"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include "calibrate/outcome_figures.h"
#include "cli/everyday_driving_table.h"
#include "cli/tying_flags.h"
#include "fit/motion_advice.h"
#include "fitcal/version.h"
#include "models/mounted_model.h"
#include "odometry/text_format.h"
#include "pages/report_text.h"
#include "validation/trajectory_family.h"

namespace fitcal::tools {

namespace {

void PrintCfTable(const std::vector<CfRow>& rows) {
  std::printf("  %-30s %10s %10s %9s\n", "CF (Eq. 14, m and rad)", "nominal", "calibrated",
              "change");
  for (const CfRow& r : rows) {
    const FinalPoseErrors& before = r.nominal;
    const FinalPoseErrors& after = r.selected;
    const double change = before.cf > 0.0 ? 100.0 * (after.cf - before.cf) / before.cf : 0.0;
    std::printf("  %-30s %10.4f %10.4f %+8.1f%%\n", r.side, before.cf, after.cf, change);
    std::printf("  %-30s %10.4f %10.4f\n", "  mean final position error [m]",
                before.mean_position_error_m, after.mean_position_error_m);
    std::printf("  %-30s %10.3f %10.3f\n", "  mean final heading error [deg]",
                RadToDeg(before.mean_abs_heading_error_rad),
                RadToDeg(after.mean_abs_heading_error_rad));
  }
}

void PrintParameters(const Robot& robot, const std::vector<double>& p, const SelectedFit& fit) {
  std::printf("\n  %-22s %12s %12s %12s %12s\n", "parameter", "nominal", "calibrated", "+-1 sigma",
              "change");
  for (int k = 0; k < robot.NumParameters(); ++k) {
    const ParameterInfo& info = robot.parameters[k];
    const double s = info.DisplayScale();
    const std::string sigma =
        fit.has_covariance && !fit.held[k] ? StrFormat("%.2g", fit.sigma[k] * s) : "-";
    const double change = p[k] - robot.nominal[k];
    using io::report_text::ChangeTerms;
    const ChangeTerms terms = io::report_text::ChangeTermsOf(
        info.unit == ParameterUnit::kAngle, IsMountPosition(robot, k), robot.nominal[k]);
    const std::string change_text =
        terms == ChangeTerms::kDegrees  ? StrFormat("%+.3f deg", change * s)
        : terms == ChangeTerms::kMetres ? StrFormat("%+.4g m", change)
                                        : StrFormat("%+.2f%%", 100.0 * change / robot.nominal[k]);
    const bool not_determined =
        k < static_cast<int>(fit.not_determined.size()) && fit.not_determined[k];
    std::printf("  %-22s %12.6f %12.6f %12s %12s%s%s%s\n", robot.LabelOf(k).c_str(),
                robot.nominal[k] * s, p[k] * s, sigma.c_str(), change_text.c_str(),
                fit.at_bound[k] ? "  AT BOUND" : "", fit.held[k] ? "  HELD" : "",
                not_determined ? "  NOT DETERMINED" : "");
  }
  if (std::find(fit.not_determined.begin(), fit.not_determined.end(), true) !=
      fit.not_determined.end()) {
    std::printf("  NOT DETERMINED: the training runs leave a direction these parameters move along "
                "(held at the nominal, below: their sigma is what the bounds allow along it, "
                "read as a uniform prior; or fitted, with a sigma wider than the bounds allow): "
                "the value is as good as your nominal there\n");
  }
  for (const HeldParameter& h : robot.held) {
    std::printf("  held: %s (%s)\n", robot.parameters[h.index].name.c_str(), h.reason.c_str());
  }
  for (const std::string& note : fit.sigma_notes) std::printf("  resolution: %s\n", note.c_str());
  if (const std::string frame =
          GroundTruthFrameLine(robot, fit.held, fit.held_reason, fit.not_determined);
      !frame.empty()) {
    std::printf("  %s\n", frame.c_str());
  }
}

// The header: the robot, the data set and how its runs split.
void PrintHeader(const CalibrationRequest& request, const Robot& robot, const RunSplit& split) {
  std::printf("fitcal %s  %s robot '%s'  data set %s\n", kVersion, robot.model.c_str(),
              robot.name.c_str(), request.dataset.c_str());
  const std::string reps = FormatRepetitionList(split.training_repetitions);
  const std::string selection = request.train_trajectories.empty()
                                    ? "repetitions " + reps
                                    : TrainingSelection(request) + "; repetitions " + reps;
  std::printf("runs: %zu training (%s), %zu validation (repetitions %s)\n", split.training.size(),
              selection.c_str(), split.validation.size(),
              FormatRepetitionList(split.validation_repetitions).c_str());
  // A split by trajectory holds families out on purpose; one by repetition may hold none out.
  if (request.train_trajectories.empty()) {
    for (const std::string& note : UnjudgedFamilyNotes(split.training, split.validation)) {
      std::printf("%s\n", note.c_str());
    }
  }
  std::printf("\n");
}

// The solvers' stop reasons: the method's fit and the track fits.
void PrintSolver(const CalibrationRequest& request, const CalibrationOutcome& o) {
  if (request.closed_forms_only) {
    std::printf("\nno fit: the robot's closed forms alone against the nominal\n");
    return;
  }
  const ModelFitResult& fit = o.fit.fit;
  // Active-set rounds are the Ceres fit's (fit/model_fit.h); NLopt methods have none.
  const std::string rounds =
      fit.active_set_rounds > 0
          ? ", " + std::to_string(fit.active_set_rounds) + " active-set rounds"
          : "";
  std::printf("\nsolver: %s, %s after %d iterations (%d evaluations%s), %.3f s (%s)\n",
              request.method->description.c_str(), fit.termination.c_str(), fit.iterations,
              o.fit.evaluations, rounds.c_str(), fit.solve_time_s, fit.message.c_str());
  if (!fit.global_start.empty()) std::printf("global start: %s\n", fit.global_start.c_str());
  if (o.track_fits) {
    std::printf(
        "track fits (training tracks): parameters alone %s after %d iterations, with the "
        "effects %s after %d\n",
        o.track_fits->without_effects.termination.c_str(), o.track_fits->without_effects.iterations,
        o.track_fits->with_effects.termination.c_str(), o.track_fits->with_effects.iterations);
  }
}

// The header, the CF table, the parameters and the solvers' stop reasons.
void PrintFit(const CalibrationRequest& request, const RobotModelInterface& model,
              const CalibrationOutcome& o) {
  PrintHeader(request, model.robot(), o.split);
  const CalibrationCandidate& selected = o.selected();
  PrintCfTable(CfRows(model, o, request.threads));
  PrintParameters(model.robot(), selected.parameters, o.selected_fit);
  for (const effects::EffectValue& e : selected.effects) {
    const effects::EffectInfo& info = effects::Info(e.id);
    for (int k = 0; k < info.num_parameters; ++k) {
      std::printf("  effect %s: %s = %.6g +- %.2g\n", info.name, info.parameter_names[k],
                  e.value[k], e.sigma[k]);
    }
  }
  PrintSolver(request, o);
}

// The clock offsets the track fit estimated, with their sigmas: every group up to a dozen, their
// range beyond.
void PrintClockOffsets(const ModelFitResult& fit, const TrackFitData& track) {
  if (!track.estimate_clock_offsets || track.clock_groups.empty()) return;
  const std::size_t n = track.clock_groups.size();
  const double bound = kMaxClockOffsetS;
  const ClockOffsetSummary s = SummariseClockOffsets(fit, track);
  std::printf("clock offsets (ground truth at encoder time + dt, |dt| <= %.2g s), %zu %s:\n",
              bound, n, n == 1 ? "group" : "groups");
  constexpr std::size_t kMaxListed = 12;
  for (std::size_t g = 0; g < n && n <= kMaxListed; ++g) {
    // A sigma of exactly 0 is the covariance that could not be computed, not a sure offset.
    const std::string sigma =
        s.sigma_s[g] > 0.0 ? StrFormat("%.3f", s.sigma_s[g]) : "? (no covariance)";
    std::printf("  %-36s %+8.3f s +- %s\n", track.clock_groups[g].c_str(),
                fit.clock_offsets_s[g], sigma.c_str());
  }
  if (n > kMaxListed) {
    std::printf("  median %+.3f s, range [%+.3f, %+.3f] s, mean sigma %.3f s\n", s.median_s,
                s.lo_s, s.hi_s, s.mean_sigma_s);
  }
  // An offset on its bound is where the fit was stopped: said, so that it is not read as a lag.
  if (s.num_on_bound == 0) return;
  std::printf("warning: %zu clock offset%s rest%s on the +-%.2g s bound (%s%s): not a measured "
              "lag; the clocks differ by more, or the offset absorbs a mismatch of the runs "
              "(--clock-offsets none, or check the ground truth's time stamps)\n",
              s.num_on_bound, s.num_on_bound == 1 ? "" : "s", s.num_on_bound == 1 ? "s" : "",
              bound, s.first_on_bound.c_str(), s.num_on_bound > 3 ? ", ..." : "");
}

// The residuals fitted, how they were chosen, and the clock offsets fitted with them.
void PrintResiduals(const CalibrationOutcome& o, const std::vector<std::string>& flag_notes) {
  std::printf("residuals: %s%s\n", ToString(o.settings.residuals),
              o.settings.residuals_auto ? " (--residuals auto)" : "");
  for (const std::string& line : o.choice_lines) std::printf("%s\n", line.c_str());
  for (const std::string& line : flag_notes) std::printf("%s\n", line.c_str());
  const ModelFitResult& fit = o.fit.fit;
  if (fit.noise_levels.estimated) {
    // Where sessions differ, one line per component (fit/noise_levels.h).
    const bool per_session = fit.noise_levels.sessions.AnyDiffers();
    std::printf("weights from the data (variance components at the solution; "
                "--position-sigma-m/--heading-sigma-deg override):%s%s\n",
                per_session ? "\n  " : " ", NoiseLevelsText(fit.noise_levels, "\n  ").c_str());
  }
  if (o.track_data) PrintClockOffsets(fit, *o.track_data);
}

// The counter glitches the loader dropped (io/log_files.h), each named above with its line.
void PrintEncoderGlitches(const std::vector<RunLog>& runs) {
  const DroppedGlitches g = CountDroppedGlitches(runs);
  if (g.intervals == 0) return;
  std::printf("encoder glitches: %d interval%s in %d run%s dropped from the fit (each named with "
              "its file:line in the warnings)\n",
              g.intervals, g.intervals == 1 ? "" : "s", g.runs, g.runs == 1 ? "" : "s");
}

// Each direction held at the nominal, and what to drive to determine it (fit/motion_advice.h).
void PrintHeldDirections(const RobotModelInterface& model, const ModelFitResult& fit,
                         const ResidualWeights& weights) {
  for (const UndeterminedDirection& d : fit.held_directions) {
    std::printf("held at nominal, not determined by the training runs: %s\n",
                d.description.c_str());
    const std::vector<MotionThatDetermines> motions =
        MotionsThatDetermine(d, model, fit.parameters, weights);
    std::printf("  %s\n", MotionAdviceLine(motions).c_str());
  }
}

// What the fit itself cannot notice, said after it: training runs whose final-pose error under
// the fit is far beyond the others' (diagnosis/degenerate_data.h: gross slip, a ground truth of
// another run), and parameters that stopped on their bounds.
void PrintFitWarnings(const RobotModelInterface& model, const RunSplit& split,
                      const ModelFitResult& fit, int threads) {
  for (const OutlierRun& o : OutlierTrainingRuns(model, split, fit, threads)) {
    std::printf("warning: run %s: final-pose error %.1fx the median run's (gross wheel slip or a "
                "ground truth of another run?); a robust loss limits its pull\n",
                o.id.c_str(), o.error_ratio);
  }
  if (std::find(fit.at_bound.begin(), fit.at_bound.end(), true) != fit.at_bound.end()) {
    std::printf(
        "warning: a parameter stopped on its bound; the model may be absorbing an effect it "
        "does not contain, or the bounds are too tight\n");
  }
}

// What the fit could not determine and what looks wrong with it.
void PrintUncertaintyAndWarnings(const RobotModelInterface& model, const CalibrationOutcome& o,
                                 int threads) {
  const ModelFitResult& fit = o.fit.fit;
  if (!fit.has_covariance) std::printf("uncertainty: %s\n", fit.covariance_message.c_str());
  PrintHeldDirections(model, fit, o.settings.weights);
  PrintFitWarnings(model, o.split, fit, threads);
}

// The gate's table, as judged when it was printed, and the effects' paired test.
void PrintGate(const CalibrationOutcome& o) {
  GateDecision gate = o.gate;
  gate.judged_on = o.gate_judged_on;
  std::printf("\nresult gate, CF on %s:\n", gate.judged_on.c_str());
  for (const std::string& line : GateLines(o.candidates, gate)) std::printf("%s\n", line.c_str());
  if (!o.effects_line.empty()) std::printf("%s\n", o.effects_line.c_str());
  if (!o.gave_way_line.empty()) std::printf("%s\n", o.gave_way_line.c_str());
  if (!o.mount_freed_line.empty()) std::printf("warning: %s\n", o.mount_freed_line.c_str());
}

// Everything up to the gate's table: the fit, the residuals, everyday driving, the warnings.
void PrintReport(const CalibrationRequest& request, const RobotModelInterface& model,
                 const CalibrationOutcome& o, const std::vector<std::string>& flag_notes) {
  PrintFit(request, model, o);
  PrintTying(o.settings.tying);
  if (!request.closed_forms_only) PrintResiduals(o, flag_notes);
  PrintEncoderGlitches(request.runs);
  // Drift per 1, 2, 5 m and ATE RMSE (validation/never_worse.h) of the nominal and the selected
  // calibration on the held-out runs (the training runs when none is held out).
  const OutcomeEverydayDriving driving = CompareOutcomeEverydayDriving(model, o, request.threads);
  PrintEverydayDrivingTable(
      driving.held_out ? "everyday driving, validation" : "everyday driving, training",
      driving.table);
  if (!request.closed_forms_only) PrintUncertaintyAndWarnings(model, o, request.threads);
  PrintGate(o);
}

// The judgements after the gate, as far as they went.
void PrintJudgements(const CalibrationOutcome& o) {
  if (o.reached >= CalibrationStage::kHalves && o.halves.judged) {
    // What is written follows only when the halves beat the nominal (the refusal says why not).
    std::printf("no held-out runs: judged on %s; %s\n", HalvesDescription(o.halves).c_str(),
                o.halves.Beats() ? "the calibration written is fitted on all of them"
                                 : "they do not beat the nominal");
  }
  if (o.reached >= CalibrationStage::kNeverWorse) {
    for (const std::string& line : o.never_worse_warnings)
      std::printf("warning: %s\n", line.c_str());
  }
  if (o.reached >= CalibrationStage::kAtBound && !o.at_bound_warning.empty()) {
    std::printf("warning: %s; written as --bounds-widened asks\n", o.at_bound_warning.c_str());
  }
}

}  // namespace

void PrintCalibrationOutcome(const CalibrationRequest& request, const RobotModelInterface& model,
                             const CalibrationOutcome& outcome,
                             const std::vector<std::string>& flag_notes) {
  for (const std::string& problem : outcome.data_warnings) {
    std::printf("warning: %s\n", problem.c_str());
  }
  if (outcome.reached >= CalibrationStage::kGate) {
    PrintReport(request, model, outcome, flag_notes);
    PrintJudgements(outcome);
  }
  if (!outcome.effects_note.empty()) std::cerr << "fitcal: " << outcome.effects_note << "\n";
  for (const std::string& reason : outcome.refusal.reasons) {
    std::cerr << "fitcal: " << reason << "\n";
  }
}

}  // namespace fitcal::tools
