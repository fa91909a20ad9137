#include "calibrate/candidates.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fit/statistics.h"
#include "io/text_file.h"
#include "odometry/text_format.h"
#include "validation/trajectory_metrics.h"

namespace fitcal {

FinalPoseErrors CandidateErrors::operator()(const CalibrationCandidate& c,
                                            const std::vector<AlignedRun>& runs) const {
  if (c.effects.empty()) return EvaluateFinalPoseErrors(model_, c.parameters, runs, threads_);
  return EvaluateFinalPoseErrors(model_, c.parameters, c.effects, runs, TracksOf(runs), threads_);
}

EffectCandidateCf CandidateErrors::Cf() const {
  return [this](const CalibrationCandidate& c, const std::vector<AlignedRun>& runs) {
    return (*this)(c, runs).cf;
  };
}

namespace {

// The fit with every direction free competes only where it stayed inside the box: along the
// directions the training runs do not determine nothing holds it, and one that ran onto a bound
// there is what the holds prevent, not a measurement (measured: an omni3 with a pose source's
// yaw fitted put delta_a on its bound with sigma 14 deg, held-out CF equal to the held fit's to
// 1e-6, and was selected). Held parameters (gauge, --hold) sit where the model put them.
CalibrationCandidate WithoutHolds(const Robot& robot, const ModelFitResult& fit,
                                  const std::string& method) {
  CalibrationCandidate c{method + " without holds", fit.unconstrained_parameters,
                         fit.unconstrained_usable};
  if (!c.usable) return c;
  const std::vector<bool> on_bound = ParametersAtBound(robot, c.parameters);
  std::string names;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (on_bound[k] && !fit.held[k]) {
      names += (names.empty() ? "" : ", ") + robot.parameters[k].name;
    }
  }
  if (!names.empty()) {
    c.usable = false;
    c.not_usable_because = "ran onto a bound along the undetermined directions (" + names + ")";
  }
  return c;
}

// A closed form measures without the box the robot YAML sets: a value outside it is no
// calibration the robot accepts (report refuses it), so it does not compete. "" when inside.
std::string OutsideBounds(const Robot& robot, const std::vector<double>& p) {
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (robot.IsHeld(k) || (p[k] >= robot.bounds[k].lo && p[k] <= robot.bounds[k].hi)) continue;
    const ParameterInfo& info = robot.parameters[k];
    const double s = info.DisplayScale();
    return info.name + " " + StrFormat("%.6g", p[k] * s) + " " + info.DisplayUnit() +
           " outside its bounds [" + StrFormat("%.6g", robot.bounds[k].lo * s) + ", " +
           StrFormat("%.6g", robot.bounds[k].hi * s) + "]";
  }
  return "";
}

}  // namespace

std::vector<CalibrationCandidate> NominalAndClosedForms(const RobotModelInterface& model,
                                                       const RunSplit& split, bool closed_forms) {
  std::vector<CalibrationCandidate> out = {
      {"nominal", model.robot().nominal, true, model.robot().effects}};
  for (const ClosedFormCalibration& c :
       closed_forms ? model.ClosedForms(split.training) : std::vector<ClosedFormCalibration>{}) {
    out.push_back({c.method, c.parameters, true, {}, c.sigma});
    out.back().not_usable_because = OutsideBounds(model.robot(), c.parameters);
    out.back().usable = out.back().not_usable_because.empty();
  }
  return out;
}

std::vector<CalibrationCandidate> Candidates(const RobotModelInterface& model,
                                             const RunSplit& split, const ModelFitResult& fit,
                                             const std::string& method, bool closed_forms) {
  std::vector<CalibrationCandidate> out = NominalAndClosedForms(model, split, closed_forms);
  out.push_back({method, fit.parameters, fit.HasFinitePoint()});
  if (!fit.held_directions.empty() && !split.validation.empty()) {
    out.push_back(WithoutHolds(model.robot(), fit, method));
  }
  return out;
}

namespace {

// "name, name" of the effects.
std::string EffectNames(const EffectModel& effects) {
  return io::Joined(effects, ", ", [](const effects::EffectValue& e) {
    return std::string(effects::Info(e.id).name);
  });
}

// The model's parameters and `effects` fitted on the training tracks (fit/effect_fit.h),
// from the nominal, as `diagnose` and `generalise --effects` fit them.
EffectFitResult FitEffects(const ResidualWeights& weights, int threads,
                           const RobotModelInterface& model, const std::vector<TrackRun>& training,
                           const EffectModel& effects) {
  EffectFitOptions o;
  o.weights = weights;
  o.num_threads = threads;
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

}  // namespace

TrackFits AddTrackFitCandidates(const ResidualWeights& weights, int threads,
                                const RobotModelInterface& model,
                                const std::vector<TrackRun>& training_tracks,
                                const EffectModel& effects_to_fit,
                                std::vector<CalibrationCandidate>* candidates) {
  TrackFits t;
  t.without_effects = FitEffects(weights, threads, model, training_tracks, {});
  t.with_effects = FitEffects(weights, threads, model, training_tracks, effects_to_fit);
  t.without_index = static_cast<int>(candidates->size());
  candidates->push_back({"track fit", t.without_effects.parameters, t.without_effects.usable});
  t.with_index = static_cast<int>(candidates->size());
  candidates->push_back({"track fit + " + EffectNames(effects_to_fit), t.with_effects.parameters,
                         t.with_effects.usable, t.with_effects.effects});
  return t;
}

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
  if (test.p < kEffectAlpha) {
    return StrFormat(
        "effects: '%s' beats '%s' run by run (paired log-ratio t = %.2f, p = %.2g < %g)",
        chosen.name.c_str(), without.name.c_str(), test.t, test.p, kEffectAlpha);
  }
  // The nominal carries effects only when the robot declares them; then some fit must stand in.
  const int best = std::max(0, BestWithoutEffects(candidates, *gate));
  gate->selected = best;
  return StrFormat(
      "effects: '%s' is not significantly better than '%s' run by run (paired log-ratio t = "
      "%.2f, p = %.2g >= %g): '%s' is selected",
      chosen.name.c_str(), without.name.c_str(), test.t, test.p, kEffectAlpha,
      candidates[best].name.c_str());
}

std::string EffectsNote(const std::vector<CalibrationCandidate>& candidates,
                        const GateDecision& gate, const RunSplit& split,
                        const CandidateErrors& errors) {
  const CalibrationCandidate& selected = candidates[gate.selected];
  if (selected.effects.empty()) return "";
  const std::vector<AlignedRun>& runs = gate.judged_on_held_out ? split.validation : split.training;
  const double alone = errors({selected.name, selected.parameters, true, {}}, runs).cf;
  const int best = BestWithoutEffects(candidates, gate);
  std::ostringstream note;
  note << "note: the calibration carries effects (" << EffectNames(selected.effects)
       << ") that an odometry of the parameters alone (a ros2_controllers controller) does "
          "not apply: there its parameters give CF "
       << alone << " on the " << gate.judged_on;
  if (best >= 0) {
    note << ", the best calibration without effects ('" << candidates[best].name << "') "
         << gate.cf[best];
  }
  note << "; for such a controller, fit without effects (no --effects, no effects: in the "
          "robot YAML)";
  return note.str();
}

}  // namespace fitcal
