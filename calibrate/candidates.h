#pragma once
// The candidates a fit hands the result gate (fit/result_gate.h): the nominal, the model's closed
// forms, the fit (and the fit without its holds), and the track fits without and with the effects
// to fit; the paired test that the effects must pass to stay selected, and what the candidates'
// final-pose errors are on any runs.

#include <optional>
#include <string>
#include <vector>

#include "calibrate/fit_methods.h"
#include "fit/effect_fit.h"
#include "fit/final_pose_errors.h"
#include "fit/result_gate.h"
#include "fit/run_split.h"

namespace fitcal {

// The final-pose errors of a candidate of the gate on some runs: replayed by the model alone, or
// with its effects against each run's ground-truth track (the same Eq. 14 at the same poses).
class CandidateErrors {
 public:
  CandidateErrors(const RobotModelInterface& model, int threads)
      : model_(model), threads_(threads) {}

  FinalPoseErrors operator()(const CalibrationCandidate& c,
                             const std::vector<AlignedRun>& runs) const;
  EffectCandidateCf Cf() const;

 private:
  const RobotModelInterface& model_;
  int threads_;
};

// The fits on the training tracks when effects are fitted (fit/effect_fit.h): the
// parameters alone and with the effects, on one objective, so that the effects are judged like
// for like; with their indices among the gate's candidates.
struct TrackFits {
  EffectFitResult without_effects, with_effects;
  int without_index = -1, with_index = -1;
};

// The nominal (with the effects the robot declares) and, when `closed_forms`, the model's closed
// forms computed from the training runs: the candidates before any fit.
std::vector<CalibrationCandidate> NominalAndClosedForms(const RobotModelInterface& model,
                                                       const RunSplit& split, bool closed_forms);

// Nominal (with the effects the robot declares), closed forms, the fit; and when the fit held
// undetermined directions and held-out runs can judge it, the fit without the holds too (on the
// training runs alone it would always win, by fitting what the data cannot tell apart), not usable
// when one of its free parameters ran onto a bound. Under --tie/--hold the closed forms stay out:
// they fit the full model, not the one asked for.
std::vector<CalibrationCandidate> Candidates(const RobotModelInterface& model,
                                             const RunSplit& split, const ModelFitResult& fit,
                                             const std::string& method, bool closed_forms);

// The track fits without and with the effects to fit (from the nominal, weighed by `weights`),
// appended to the gate's candidates.
TrackFits AddTrackFitCandidates(const ResidualWeights& weights, int threads,
                                const RobotModelInterface& model,
                                const std::vector<TrackRun>& training_tracks,
                                const EffectModel& effects_to_fit,
                                std::vector<CalibrationCandidate>* candidates);

// An effect earns its place as a calibration earns it against the nominal: the gate's choice,
// when it carries effects, must have lower per-run CFs than the same track fit without them
// (like for like: the track objective alone must not be credited to the effects), by the
// one-sided paired test on the log ratios (stats::PairedLogRatioTest, p < kEffectAlpha) on the
// runs that judged; otherwise the best candidate without effects is selected. The line that says
// which, or empty.
constexpr double kEffectAlpha = 0.01;
std::string RequireEffectsToEarnTheirPlace(const std::vector<CalibrationCandidate>& candidates,
                                           const RunSplit& split, const CandidateErrors& errors,
                                           const TrackFits& track_fits, GateDecision* gate);

// When the selected calibration carries effects: what an odometry of the parameters alone (a
// ros2_controllers controller) gets from it, and from the best candidate without effects, as a
// note ("note: ..."); empty otherwise.
std::string EffectsNote(const std::vector<CalibrationCandidate>& candidates,
                        const GateDecision& gate, const RunSplit& split,
                        const CandidateErrors& errors);

}  // namespace fitcal
