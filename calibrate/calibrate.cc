#include "calibrate/calibrate.h"

#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include "calibrate/calibration_record.h"
#include "calibrate/checks_before_fitting.h"
#include "calibrate/choice_by_transfer.h"
#include "calibrate/mount_freed.h"
#include "calibrate/never_worse_gate.h"
#include "calibrate/reading_resolution_uncertainty.h"
#include "calibrate/track_residuals.h"
#include "fit/final_pose_errors.h"
#include "fit/model_fit.h"
#include "fit/result_gate.h"
#include "models/mounted_model.h"
#include "odometry/text_format.h"
#include "validation/never_worse.h"

namespace fitcal {

int CalibrationOutcome::exit_code() const {
  if (refusal.exit_code != 0) return refusal.exit_code;
  return stopped_early.empty() ? 0 : 6;
}

namespace {

// Sets the refusal; false, so that a stage ends with `return Refuse(...)`.
bool Refuse(CalibrationOutcome* out, int exit_code, std::vector<std::string> reasons) {
  out->refusal = {exit_code, std::move(reasons)};
  return false;
}

// The training runs split off and checked, the effect fit's tracks and the method's track
// residuals prepared (--residuals auto resolved).
bool PrepareData(const CalibrationRequest& r, const RobotModelInterface& model,
                 CalibrationOutcome* out, std::optional<std::vector<TrackRun>>* training_tracks) {
  out->split = SplitOfRequest(r);
  if (const std::string absent = AbsentRepetitionRefusal(r); !absent.empty()) {
    return Refuse(out, 2, {absent});
  }
  if (out->split.training.empty()) {
    return Refuse(out, 2, {"no run of " + r.dataset + " is a training run (" +
                           TrainingSelection(r) + ")"});
  }
  std::string reason;
  if (const int code = CheckBeforeFitting(r, model, out->split, &out->data_warnings, &reason)) {
    return Refuse(out, code, {reason});
  }
  if (!r.effects_to_fit.empty()) {
    *training_tracks = TrainingTracks(r.dataset, model.robot(), r.runs, out->split, &reason);
    if (!*training_tracks) return Refuse(out, 2, {reason});
  }
  reason = PrepareTrackResiduals(r.method->name, out->split.training, &out->settings,
                                 &out->track_data);
  if (!reason.empty()) return Refuse(out, 2, {reason});
  return true;
}

// The fit of all the training runs, with the residual kind and the track's heading chosen by
// transfer and its weights on the held-out runs first, when the request leaves them to the data
// (not with effects to fit).
void FitTrainingRuns(const CalibrationRequest& r, const RobotModelInterface& model,
                     CalibrationOutcome* out, std::string* objective_note) {
  if (r.closed_forms_only) {
    out->fit.objective = "the model's closed form, no fit";
    return;
  }
  // The fit of all the training runs when a choice by transfer made it (and kept its kind).
  std::optional<ModelFitMethodOutcome> chosen_fit;
  if (r.effects_to_fit.empty()) {
    FoldFits fold_fits;
    out->choice_lines =
        ChooseResidualsByTransfer(*r.method, r.threads, model, out->split, &out->settings,
                                  &out->track_data, &chosen_fit, &fold_fits);
    for (const std::string& line : ChooseTrackObjectiveByTransfer(
             *r.method, r.threads, model, out->split, &out->settings, &out->track_data,
             &chosen_fit, &fold_fits, objective_note)) {
      out->choice_lines.push_back(line);
    }
    for (const std::string& line : ChooseWeightsOnHeldOutRuns(
             *r.method, r.threads, model, out->split, &out->settings, &chosen_fit,
             objective_note)) {
      out->choice_lines.push_back(line);
    }
  }
  // The cheap count first: a data set with too few residuals pays for no halves' fits.
  const std::string refusal = DegreesOfFreedomRefusal(
      out->split, out->settings, out->track_data,
      NumFreeWithTying(model, out->settings.tying) + r.effects_to_fit.size());
  if (!refusal.empty()) {
    Refuse(out, 1, {r.dataset + ": " + refusal});
    return;
  }
  if (!chosen_fit && r.effects_to_fit.empty()) {
    chosen_fit = FitAskedFinalPoseFromTheTrackToo(*r.method, model, out->split.training,
                                                  out->settings);
  }
  out->fit = chosen_fit ? std::move(*chosen_fit)
                        : r.method->run_model(out->split.training, model, out->settings);
  const ModelFitResult& whole = out->fit.fit;
  out->halves = JudgeMethodOnHeldOutHalves(
      *r.method, r.threads, r.time_blocks, out->settings,
      whole.HasFinitePoint() ? whole.parameters : std::vector<double>{}, model,
      out->split);
}

// The bounds' rule (JudgeBounds) applied among the candidates: a selected candidate with a
// parameter on its bound (its description's at_bound, out->selected_fit) gives way to the best
// candidate inside its bounds that beats the nominal too (stop 65's sweep: an ASOC fit with
// --train-reps 1-99 ended with d_2_3 on its bound and was refused while its geometric closed form,
// inside its bounds, beat the nominal by 98 %); true when it did. With none, the selection stands
// and JudgeBounds refuses it with the reason.
bool GiveWayOnABound(const Robot& robot, const std::string& method, CalibrationOutcome* out) {
  const int selected = out->gate.selected;
  if (selected == 0) return false;
  const CalibrationCandidate& c = out->candidates[selected];
  const std::string refusal =
      AtBoundRefusal(robot, c.name, c.parameters, out->selected_fit.at_bound);
  if (refusal.empty()) return false;
  // The other candidates by the parameters' own values (a closed form's too; the method's fit
  // by its own rule, which leaves out what it held).
  const int next = BestCandidateInsideTheBounds(out->candidates, out->gate, [&](int i) {
    const CalibrationCandidate& other = out->candidates[i];
    return other.name == method ? out->fit.fit.at_bound
                                : ParametersAtBound(robot, other.parameters);
  });
  if (next == 0) return false;
  out->gate.selected = next;
  out->gave_way_line = refusal + "; selected instead: '" + out->candidates[next].name +
                       "', inside its bounds (--bounds-widened would write '" + c.name + "')";
  return true;
}

// The candidates fitted and judged by the gate, the effects' paired test, and what the selected
// one carries; false when it has no uncertainty to write.
bool SelectCandidate(const CalibrationRequest& r, const RobotModelInterface& model,
                     const std::optional<std::vector<TrackRun>>& training_tracks,
                     const CandidateErrors& errors, const std::string& objective_note,
                     CalibrationOutcome* out) {
  const RunSplit& split = out->split;
  out->candidates =
      r.closed_forms_only
          ? NominalAndClosedForms(model, split, true)
          : Candidates(model, split, out->fit.fit, r.method->name, out->settings.tying.empty());
  if (out->candidates.size() == 1) {  // only with closed_forms_only: a fit is always a candidate
    return Refuse(out, 1, {r.dataset + ": the robot's model computes no closed form from the "
                           "training runs (" + TrainingSelection(r) + "); nothing written"});
  }
  if (training_tracks) {
    out->track_fits = AddTrackFitCandidates(r.settings.weights, r.threads, model,
                                            *training_tracks, r.effects_to_fit, &out->candidates);
  }
  out->gate = SelectCalibration(model, out->candidates, split.training, split.validation,
                                r.threads, errors.Cf());
  if (out->track_fits) {
    out->effects_line = RequireEffectsToEarnTheirPlace(out->candidates, split, errors,
                                                       *out->track_fits, &out->gate);
  }
  const auto describe_selected = [&] {
    out->selected_fit =
        DescribeSelected(model.robot(), out->candidates, out->gate.selected, r.method->name,
                         out->fit.objective + objective_note, out->fit.fit, out->track_fits);
  };
  describe_selected();
  if (!r.bounds_widened && GiveWayOnABound(model.robot(), r.method->name, out)) {
    describe_selected();
  }
  if (out->gate.selected != 0 && out->selected().name == r.method->name) {
    AddReadingResolutionUncertainty(*r.method, out->settings, model, split.training,
                                    ReadingResolutionsOf(model.robot(), r.runs),
                                    out->selected().parameters, &out->selected_fit);
  }
  std::string refusal;
  if (out->gate.selected != 0 && r.will_write) {
    refusal = AddPropagatedUncertainty(model, out->selected(), split.training, &out->selected_fit);
  }
  MarkWiderThanTheBounds(model.robot(), &out->selected_fit);
  return refusal.empty() || Refuse(out, 1, {r.dataset + ": " + refusal});
}

// What to try when the training runs, chosen by repetition, leave directions undetermined that
// the held-out runs may drive: a session of several paths, each repeated, puts its first paths in
// repetitions 1-5 and the others in the held-out runs (the OptiOdom sessions fitted alone: 9 get
// this line, omni3's and omni4's; with --train-reps 1-99, 8 of them are written, and omni3
// circular 221220201701's calibration beats the nominal on the robot's other sessions, CF 0.2594
// -> 0.1037). Empty otherwise.
std::string SplitHint(const CalibrationRequest& r, const CalibrationOutcome& out) {
  if (!r.training_ids.empty() || !r.train_trajectories.empty() || out.split.validation.empty() ||
      out.fit.fit.held_directions.empty()) {
    return "";
  }
  int last = 1;
  for (const RunLog& run : r.runs) last = std::max(last, run.repetition);
  return "the training runs (" + TrainingSelection(r) + ") leave directions undetermined (held "
         "at nominal, above) that the held-out runs may drive: --train-reps 1-" +
         std::to_string(std::max(last, 99)) +
         " fits every run and judges on held-out halves of them";
}

// When a fit with ties or holds does not beat the nominal even on the runs it was fitted on, the
// held-out runs are not to blame: the robot does not obey them (stop 72's D-F7: a tie of two
// unequal wheels, training CF 0.98 -> 1.78, was blamed on the split). Empty without ties or holds
// (a track fit may lose on the final poses of its own runs to a nominal already close), or when a
// fitted candidate beats the nominal on its training runs.
std::string MisfitHint(const CalibrationRequest& r, const CandidateErrors& errors,
                       const CalibrationOutcome& out) {
  const std::vector<AlignedRun>& training = out.split.training;
  if (r.closed_forms_only || training.empty() || out.settings.tying.empty()) return "";
  double fitted = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 1; i < out.candidates.size(); ++i) {
    if (!out.candidates[i].usable) continue;
    const double cf = errors(out.candidates[i], training).cf;
    if (!(cf >= fitted)) fitted = cf;  // the lowest; NaN (none yet) gives way
  }
  const double nominal = errors(out.candidates[0], training).cf;
  if (std::isnan(fitted) || !(fitted >= nominal)) return "";
  return "no calibration beats the nominal even on the training runs it was made from (CF " +
         StrFormat("%.4f -> %.4f at best", nominal, fitted) +
         "): the robot does not obey the ties or holds asked for (--tie, --hold)";
}

// The gate's verdict; its table says it judged on the training runs when the halves judge.
bool JudgeGate(const CalibrationRequest& r, const CandidateErrors& errors,
               CalibrationOutcome* out) {
  out->reached = CalibrationStage::kGate;
  if (out->halves.judged) {
    out->gate.judged_on = "training runs (" + std::to_string(out->split.training.size()) +
                          "; no held-out runs: judged on held-out " +
                          (out->halves.by_time ? "time blocks" : "halves") + ", below)";
  }
  out->gate_judged_on = out->gate.judged_on;
  if (out->gate.improves_on_nominal()) return true;
  std::vector<std::string> reasons = {"no calibration beats the nominal robot on the " +
                                      out->gate.judged_on + "; nothing written"};
  std::string hint = MisfitHint(r, errors, *out);
  if (hint.empty()) hint = SplitHint(r, *out);
  if (!hint.empty()) reasons.push_back(std::move(hint));
  return Refuse(out, 5, std::move(reasons));
}

// Why the fits of one half do not beat the nominal on the other, one reason a line.
std::vector<std::string> HalvesRefusalReasons(const HalvesJudgement& j) {
  std::vector<std::string> reasons;
  const std::string half = j.by_time ? "the run's time" : "the training runs";
  for (const HalvesGroup& g : j.groups) {
    if (g.Beats()) continue;
    const std::string which =
        g.block_count > 0 ? " (" + std::to_string(g.block_count) + " blocks)" : "";
    if (!(g.calibrated_cf < g.nominal_cf)) {
      std::ostringstream line;
      line << "fitted on half of " << half << which
           << ", the calibration does not beat the nominal on the other half (CF " << g.nominal_cf
           << " -> " << g.calibrated_cf << ")";
      reasons.push_back(line.str());
    }
    for (const std::string& line :
         NeverWorseRefusals("the fit of one half" + which, g.never_worse)) {
      reasons.push_back(line);
    }
  }
  reasons.push_back("the runs do not determine the parameters; record more driving; nothing "
                    "written");
  return reasons;
}

// With nothing held out: the fits of one half must beat the nominal on the other; the record
// then says it was judged on them.
bool JudgeHalves(CalibrationOutcome* out) {
  out->reached = CalibrationStage::kHalves;
  if (!out->halves.judged) return true;
  if (!out->halves.Beats()) return Refuse(out, 5, HalvesRefusalReasons(out->halves));
  out->gate.judged_on = HalvesDescription(out->halves);
  return true;
}

// A calibration better than the nominal on the held-out runs as a whole may still be worse on
// one kind of run, or in drift or ATE, beyond the runs' own scatter (validation/never_worse.h);
// it is then not written.
bool JudgeNeverWorse(const RobotModelInterface& model, int threads, CalibrationOutcome* out) {
  out->reached = CalibrationStage::kNeverWorse;
  if (!out->gate.judged_on_held_out || out->gate.selected == 0) return true;
  const std::vector<AlignedRun>& held_out = out->split.validation;
  NeverWorseVerdict verdict = JudgeNeverWorseThanNominal(
      model, out->candidates[0], out->selected(), held_out, TracksOf(held_out), threads);
  out->never_worse_warnings = std::move(verdict.warnings);
  return verdict.refusals.empty() || Refuse(out, 5, std::move(verdict.refusals));
}

// A parameter on its bound refuses the calibration, unless the bounds were widened on purpose.
bool JudgeBounds(const CalibrationRequest& r, const Robot& robot, CalibrationOutcome* out) {
  out->reached = CalibrationStage::kAtBound;
  const CalibrationCandidate& selected = out->selected();
  std::string refusal =
      AtBoundRefusal(robot, selected.name, selected.parameters, out->selected_fit.at_bound);
  if (!refusal.empty()) {
    refusal += HeldMountNote(robot, selected.parameters, out->selected_fit.held);
  }
  if (refusal.empty() || out->gate.selected == 0) return true;
  if (!r.bounds_widened) return Refuse(out, 5, {refusal + "; nothing written"});
  out->at_bound_warning = refusal;
  return true;
}

// What is said of the selected calibration beyond the gate, and its record.
void Conclude(const CalibrationRequest& r, const RobotModelInterface& model,
              const CandidateErrors& errors, CalibrationOutcome* out) {
  out->reached = CalibrationStage::kDone;
  out->effects_note = EffectsNote(out->candidates, out->gate, out->split, errors);
  const ModelFitResult& fit = out->fit.fit;
  const bool selected_is_fit = out->selected().name == r.method->name;
  if (r.will_write) {
    out->record = MakeRecord(r, model, out->split, out->candidates, out->gate, out->selected_fit,
                             errors);
    if (out->track_data && selected_is_fit) {
      RecordClockOffsets(fit, *out->track_data, out->settings.clock_grouping, &*out->record);
    }
  }
  if (fit.stopped_early && selected_is_fit) {
    const bool ceres = IsCeresMethod(r.method->name);
    out->stopped_early = "warning: the written calibration is the solver's last point (" +
                         fit.termination + (ceres ? " at the iteration" : " at the evaluation") +
                         " limit): it beats the nominal, but check it or raise " +
                         (ceres ? "--max-iterations" : "--max-evaluations");
  }
  if (!fit.not_at_a_minimum.empty() && selected_is_fit) {
    out->stopped_early = "warning: the written calibration is " + r.method->name +
                         "'s last point, and " + fit.not_at_a_minimum +
                         ": it beats the nominal, but --polish finishes the search with a local "
                         "method (or fit with --method ceres)";
  }
}

void Run(const CalibrationRequest& r, const RobotModelInterface& model, CalibrationOutcome* out) {
  out->settings = r.settings;
  std::optional<std::vector<TrackRun>> training_tracks;
  if (!PrepareData(r, model, out, &training_tracks)) return;
  std::string objective_note;
  FitTrainingRuns(r, model, out, &objective_note);
  if (out->refusal.exit_code != 0) return;
  const CandidateErrors errors(model, r.threads);
  if (!SelectCandidate(r, model, training_tracks, errors, objective_note, out)) return;
  if (!JudgeGate(r, errors, out) || !JudgeHalves(out) || !JudgeNeverWorse(model, r.threads, out) ||
      !JudgeBounds(r, model.robot(), out)) {
    return;
  }
  Conclude(r, model, errors, out);
}

// A robot that moves sideways holds its mount's x and y at the guess: the wheel distances take
// up an error in it, as far as their bounds let them. Where they cannot, the fit with x and y
// free (the direction analysis then holds the gauge at the nominal, distances and mount
// together) predicts the training runs better, and the whole calibration is made with it; the
// line says so. Not when that calibration is refused (HeldMountNote then names the guess).
void FitAMountTheWheelsCannotAbsorb(const CalibrationRequest& r, const RobotModelInterface& model,
                                    CalibrationOutcome* out) {
  const auto* mounted = dynamic_cast<const MountedModel*>(&model);
  const ModelFitResult& held = out->fit.fit;
  if (mounted == nullptr || r.closed_forms_only || !held.HasFinitePoint()) return;
  const RobotModelPtr freed = mounted->WithSidewaysMountFreed();
  if (!freed) return;
  const ModelFitResult fitted = r.method->run_model(out->split.training, *freed, out->settings).fit;
  if (!fitted.HasFinitePoint()) return;
  const std::vector<AlignedRun>& training = out->split.training;
  const double held_cf = EvaluateFinalPoseErrors(model, held.parameters, training, r.threads).cf;
  const double free_cf = EvaluateFinalPoseErrors(*freed, fitted.parameters, training, r.threads).cf;
  if (!(free_cf < kMountFreedCfRatio * held_cf)) return;
  CalibrationOutcome again;
  Run(r, *freed, &again);
  if (again.refusal.exit_code != 0) return;  // the held one's refusal names the guess
  const std::string line =
      MountFreedLine(*mounted, again.selected().parameters, held.parameters, held_cf, free_cf);
  *out = std::move(again);
  out->mount_freed_line = line;
  out->mount_freed_model = freed;
}

}  // namespace

CalibrationOutcome Calibrate(const CalibrationRequest& request, const RobotModelInterface& model) {
  CalibrationOutcome out;
  Run(request, model, &out);
  FitAMountTheWheelsCannotAbsorb(request, model, &out);
  out.settings.track = nullptr;  // it pointed into out.track_data, which moves with the outcome
  return out;
}

}  // namespace fitcal
