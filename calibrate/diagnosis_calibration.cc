#include "calibrate/diagnosis_calibration.h"

#include <algorithm>

#include "calibrate/calibration_record.h"
#include "calibrate/checks_before_fitting.h"
#include "calibrate/fit_methods.h"
#include "calibrate/reading_resolution_uncertainty.h"
#include "fit/correlation.h"
#include "fit/model_fit.h"
#include "fit/result_gate.h"
#include "models/mounted_model.h"
#include "validation/propagated_uncertainty.h"

namespace fitcal {

namespace {

// The candidate a fit makes, carrying that fit's own uncertainty.
DiagnoseChoice FitChoice(const std::string& name, const std::vector<double>& parameters,
                         const EffectModel& effects, double cf_after, bool has_covariance,
                         const std::vector<double>& sigma, const Eigen::MatrixXd& correlation) {
  DiagnoseChoice c{name, parameters, effects, 0.0, cf_after};
  if (has_covariance && correlation.rows() == static_cast<Eigen::Index>(sigma.size())) {
    c.sigma = sigma;
    c.correlation = correlation;
  }
  return c;
}

// The candidates with their held-out CFs, the nominal first.
std::vector<DiagnoseChoice> Candidates(const RobotModelInterface& model,
                                       const SplitOf<TrackRun>& split,
                                       const DiagnoseResult& result, int threads) {
  const std::vector<double>& nominal = model.robot().nominal;
  const auto cf = [&](const std::vector<double>& p, const EffectModel& e) {
    return ScoreModel(model, p, e, split.validation, {}, threads).cf;
  };
  const ModelFitResult& declared = result.declared;
  const EffectFitResult& base = result.base;
  const EffectFitResult& final_fit = result.final_fit;
  std::vector<DiagnoseChoice> candidates = {{"nominal", nominal, {}, 0.0, cf(nominal, {})}};
  if (declared.usable) {
    candidates.push_back(FitChoice("declared final-pose fit", declared.parameters, {},
                                   result.declared_validation.cf, declared.has_covariance,
                                   declared.sigma, declared.correlation));
  }
  candidates.push_back(FitChoice("track fit", base.parameters, {}, cf(base.parameters, {}),
                                 base.has_covariance, base.sigma, base.correlation));
  if (result.effects_named) {
    candidates.push_back(FitChoice("track fit + effects", final_fit.parameters, final_fit.effects,
                                   result.final_validation.cf, final_fit.has_covariance,
                                   final_fit.sigma, final_fit.correlation));
  }
  return candidates;
}

// Which of a candidate's parameters rest on a bound of the robot's box (none for the nominal).
std::vector<bool> OnItsBounds(const Robot& robot, std::size_t index, const DiagnoseChoice& c) {
  if (index == 0) return std::vector<bool>(robot.parameters.size(), false);
  return ParametersAtBound(robot, c.parameters);
}

bool AnyOf(const std::vector<bool>& flags) {
  return std::find(flags.begin(), flags.end(), true) != flags.end();
}

// The lowest held-out CF (the nominal first wins ties) among the candidates with no parameter on
// a bound - the bounds' rule of fit (fit/result_gate.h AtBoundRefusal): a value the data pushed
// as far as the box allows is not written (before, diagnose wrote a simulated omni3, its mount
// guessed 0.37 m off, with its wheel distances and angles on their bounds, sigmas 4.9 m and 220
// deg). *on_bound: why the lowest of all gave way, or empty. With the CFs the record carries.
DiagnoseChoice Select(const RobotModelInterface& model, const SplitOf<TrackRun>& split,
                      int threads, std::vector<DiagnoseChoice>* candidates,
                      std::string* on_bound) {
  std::vector<DiagnoseChoice>& c = *candidates;
  const Robot& robot = model.robot();
  std::size_t best = 0, lowest = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    if (c[i].cf_after < c[lowest].cf_after) lowest = i;
    if (c[i].cf_after < c[best].cf_after && !AnyOf(OnItsBounds(robot, i, c[i]))) best = i;
  }
  if (lowest != best) {
    *on_bound = AtBoundRefusal(robot, c[lowest].name, c[lowest].parameters,
                               OnItsBounds(robot, lowest, c[lowest])) +
                HeldMountNote(robot, c[lowest].parameters, robot.HeldFlags());
  }
  c[best].cf_before = c[0].cf_after;
  const auto cf_training = [&](const DiagnoseChoice& d) {
    return ScoreModel(model, d.parameters, d.effects, split.training, {}, threads).cf;
  };
  c[best].cf_training_before = cf_training(c[0]);
  c[best].cf_training_after = cf_training(c[best]);
  return c[best];
}

// The chosen calibration beats the nominal on the held-out runs as a whole; it must not be worse
// on a kind of run, in drift or ATE beyond the runs' scatter either (the rule fit applies).
NeverWorseVerdict JudgeNeverWorse(const RobotModelInterface& model,
                                  const SplitOf<TrackRun>& split, const DiagnoseChoice& nominal,
                                  const DiagnoseChoice& choice, int threads) {
  std::vector<AlignedRun> runs;
  std::vector<const GroundTruthTrack*> tracks;
  for (const TrackRun& r : split.validation) {
    runs.push_back(r.aligned);
    tracks.push_back(&r.track);
  }
  return JudgeNeverWorseThanNominal(
      model, {nominal.name, nominal.parameters, true, nominal.effects},
      {choice.name, choice.parameters, true, choice.effects}, runs, tracks, threads);
}

// A written calibration never carries sigma: null. When the fit that made the chosen parameters
// had no covariance of its own, they get the one propagated through the training runs' final
// poses (validation/propagated_uncertainty.h); "" when done, else why not (nothing is written).
std::string AddUncertainty(const RobotModelInterface& model, const SplitOf<TrackRun>& split,
                           DiagnoseChoice* choice, bool* propagated) {
  const std::size_t n = model.robot().parameters.size();
  if (choice->sigma.size() == n) return "";
  const PropagatedUncertainty u =
      PropagateFinalPoseUncertainty(model, choice->parameters, AlignedOf(split.training));
  if (!u.ok || u.sigma.size() != n) {
    return "the chosen calibration ('" + choice->name + "') has no uncertainty: " + u.message +
           "; nothing written";
  }
  choice->sigma = u.sigma;
  choice->correlation = CorrelationOf(u.covariance);
  *propagated = true;
  return "";
}

// The angle channels' resolution in the chosen calibration's sigmas, as fit adds it
// (calibrate/reading_resolution_uncertainty.h): each quantised channel's parameter move, found by
// refitting the declared final-pose fit from its own optimum with the channel shifted, joins the
// chosen fit's covariance (a track fit's own refit is not at hand here; the same constant bias
// moves both alike). Before, diagnose wrote the OptiOdom tricycle's steering offset with sigma
// 0.015 deg where fit wrote 0.13 (the encoder's 0.45 deg steps).
std::vector<std::string> AddResolution(const DiagnosisCalibrationRequest& request,
                                       const RobotModelInterface& model,
                                       const SplitOf<TrackRun>& split,
                                       const ModelFitResult& declared, DiagnoseChoice* choice) {
  SelectedFit fit;
  fit.has_covariance = true;
  fit.sigma = choice->sigma;
  fit.correlation = choice->correlation;
  const std::vector<ReadingResolution> resolutions =
      ReadingResolutionsOf(model.robot(), *request.runs);
  const bool quantised = std::any_of(resolutions.begin(), resolutions.end(),
                                     [](const ReadingResolution& r) { return r.step_rad > 0.0; });
  if (!quantised) return {};
  if (!declared.usable) {
    return {"the sigmas leave the angle channels' resolution out: the declared final-pose fit, "
            "whose refit measures it, did not converge"};
  }
  FitMethodSettings settings;
  settings.threads = request.threads;
  AddReadingResolutionUncertainty(*FindFitMethod("ceres"), settings, model,
                                  AlignedOf(split.training), resolutions, declared.parameters,
                                  &fit);
  choice->sigma = fit.sigma;
  choice->correlation = fit.correlation;
  return fit.sigma_notes;
}

std::string ObjectiveOf(const DiagnoseChoice& choice) {
  return choice.name == "declared final-pose fit"
             ? "sum over runs of the squared final-pose error (m and rad)"
             : "sum over runs of the mean squared track error (m and rad)";
}

// What the calibrated YAML records of the diagnosis: the chosen candidate, its objective, the
// training and held-out runs, and the CF before and after on both.
io::CalibrationBlock MakeRecord(const DiagnosisCalibrationRequest& request, const Robot& robot,
                                const SplitOf<TrackRun>& split, const DiagnoseResult& result,
                                const DiagnoseChoice& choice) {
  io::CalibrationBlock block;
  block.method = "diagnose: " + choice.name;
  block.objective = ObjectiveOf(choice);
  block.termination = result.final_fit.termination;
  RecordTrainingRuns(request.dataset, *request.runs, request.train_trajectories, split, &block);
  block.cf_training_before = choice.cf_training_before;
  block.cf_training_after = choice.cf_training_after;
  block.cf_validation_before = choice.cf_before;
  block.cf_validation_after = choice.cf_after;
  block.selected = choice.name;
  block.selected_on = "held-out runs (" + std::to_string(split.validation.size()) + ")";
  for (const HeldParameter& h : robot.held) block.held.push_back(robot.parameters[h.index].name);
  block.has_uncertainty = static_cast<int>(choice.sigma.size()) == robot.NumParameters();
  if (block.has_uncertainty) {
    block.sigma = choice.sigma;
    block.correlation = choice.correlation;
  }
  return block;
}

}  // namespace

DiagnosisCalibration CalibrateOnDiagnosis(const DiagnosisCalibrationRequest& request,
                                          const RobotModelInterface& model,
                                          const SplitOf<TrackRun>& split,
                                          const DiagnoseResult& result) {
  DiagnosisCalibration out;
  // Training runs that stand still teach the diagnosis nothing either: a fit on them picks any
  // value (on a simulated drive it went to the bounds) and the gate's choice is noise.
  std::vector<std::string> training_ids;
  for (const TrackRun& run : split.training) training_ids.push_back(run.aligned.id);
  if (std::string still =
          StillTrainingRunsRefusal(request.dataset, *request.runs, training_ids, model.robot());
      !still.empty()) {
    out.refusal = {1, {std::move(still)}};
    return out;
  }
  out.gate = Candidates(model, split, result, request.threads);
  if (!result.declared.usable) {
    out.left_out_line = "declared final-pose fit: not a candidate, it did not converge (" +
                        result.declared.termination + ")";
  }
  std::string on_bound;
  out.choice = Select(model, split, request.threads, &out.gate, &on_bound);
  if (out.choice.name == "nominal") {
    out.refusal = {5, {on_bound.empty() ? "no calibration beats the nominal robot on the "
                                          "held-out runs; nothing written"
                                        : on_bound + "; nothing written"}};
    return out;
  }
  if (!on_bound.empty()) {
    out.gave_way_line = on_bound + "; selected instead: '" + out.choice.name +
                        "', inside its bounds";
  }
  out.reached = CalibrationStage::kNeverWorse;
  NeverWorseVerdict verdict =
      JudgeNeverWorse(model, split, out.gate.front(), out.choice, request.threads);
  out.never_worse_warnings = std::move(verdict.warnings);
  if (!verdict.refusals.empty()) {
    out.refusal = {5, std::move(verdict.refusals)};
    return out;
  }
  const std::string refusal =
      AddUncertainty(model, split, &out.choice, &out.uncertainty_propagated);
  if (!refusal.empty()) {
    out.refusal = {1, {refusal}};
    return out;
  }
  out.sigma_notes = AddResolution(request, model, split, result.declared, &out.choice);
  out.reached = CalibrationStage::kDone;
  out.record = MakeRecord(request, model.robot(), split, result, out.choice);
  return out;
}

DiagnosisSplit SplitForDiagnosis(const std::vector<RunLog>& runs, const Robot& robot,
                                 const std::string& train_reps,
                                 const std::string& train_trajectories) {
  DiagnosisSplit out{
      SplitForFit(PrepareTrackRuns(runs, WheelChannelMask(robot)), train_reps, train_trajectories),
      ""};
  out.text = train_trajectories.empty()
                 ? "training repetitions " + FormatRepetitionList(out.training_repetitions)
                 : "training trajectories matching '" + train_trajectories + "'";
  return out;
}

Refusal RefusalOfDeclaredEffects(const Robot& robot, const std::string& robot_path) {
  if (robot.effects.empty()) return {};
  return {2, {robot_path + ": the robot already declares effects; diagnose starts from a robot "
                           "YAML without an effects: list"}};
}

Refusal RefusalOfSplit(const DiagnosisSplit& split) {
  if (!split.training.empty() && !split.validation.empty()) return {};
  return {2, {"diagnose needs training and held-out runs; got " +
              std::to_string(split.training.size()) + " training and " +
              std::to_string(split.validation.size()) + " validation runs (" + split.text + ")"}};
}

// From a guess far off, the final poses alone may leave the declared fit short of converging where
// the tracks find the truth (stop 67's sweep: diff_drive_073, a mounted differential drive with its
// pose source guessed 0.27 m off, NO_CONVERGENCE on final poses, `fit` on the tracks 0.030).
Refusal RefusalOfUnconvergedFits(const DiagnoseResult& result) {
  if (!result.declared.HasFinitePoint()) {
    return {3, {"the declared fit did not converge (" + result.declared.termination +
                "); nothing written"}};
  }
  if (!result.final_fit.usable) {
    return {3, {"the track fit did not converge (" + result.final_fit.termination +
                "); nothing written"}};
  }
  return {};
}

}  // namespace fitcal
