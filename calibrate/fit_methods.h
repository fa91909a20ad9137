#pragma once
// The registry of fit methods behind `--method` (fit) and `--methods` (compare): Ceres
// (Levenberg-Marquardt or dogleg) and every NLopt method of fit/nlopt_search.h, one entry each,
// for every robot model: `run_model` fits any model through the seam (fit/model_fit.h,
// fit/model_nlopt_fit.h).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fit/model_fit.h"
#include "fit/nlopt_search.h"
#include "models/model_interface.h"

namespace fitcal {

// The solver flags (cli/solver_options.h) checked and in the solvers' terms (enums, SI
// weights), with the worker threads and a progress callback; each method uses the ones that apply
// to it.
struct FitMethodSettings {
  int threads = 0;
  int max_iterations = 100;  // Ceres iterations per solve
  ResidualWeights weights;
  // Ceres with track residuals: weights from noise levels estimated by the fit
  // (fit/noise_levels.h); `weights` start it. Off when the user gave a sigma.
  bool estimate_weights = true;
  // --weights auto / --track-heading auto: the track objective chosen by transfer among those the
  // flags allow (validation/track_objective_transfer.h); estimate_weights and track_heading hold
  // the default candidate's until the command chooses.
  bool weights_auto = false;
  bool track_heading_auto = false;
  // Ceres: kSumOfSquares by default; NLopt: Eq. 14 by default (see the option docs).
  bool objective_set = false;
  FinalPoseObjective objective = FinalPoseObjective::kSumOfSquares;
  // Ceres only: what the residuals compare; kTrack and kBoth need `track` (the training runs'
  // tracks, set by the command that has the ground truth).
  ResidualKind residuals = ResidualKind::kFinalPose;
  bool residuals_auto = false;  // --residuals auto: ResolveAutoResiduals sets `residuals`
  ClockGrouping clock_grouping = ClockGrouping::kPerSession;
  TrackHeading track_heading = TrackHeading::kFromStart;
  const TrackFitData* track = nullptr;
  CeresRobustLoss loss = CeresRobustLoss::kNone;  // Ceres only
  double loss_scale = 0.05;
  std::uint64_t seed = 1;                              // NLopt only
  int max_evaluations = 20000;                         // NLopt only
  bool local_polish = false;                           // NLopt global methods only
  std::function<void(const NloptProgress&)> progress;  // NLopt only
  // Groups of parameters sharing one value and parameters held at the nominal (every method).
  ParameterTying tying;
  // Ceres with track residuals: the first fit's track weights when they differ from `weights`
  // (e.g. the noise levels a fit of more runs settled on, so that a fold's estimate settles fast).
  std::optional<ResidualWeights> track_weights;
  // Ceres: where the fit starts (empty: the robot's nominal), e.g. a fit of more runs whose
  // neighbourhood a fold's fit will end in. NLopt methods search their box and ignore it.
  std::vector<double> start;
  // Ceres: a fold's fit for a choice by transfer (calibrate/choice_by_transfer.h), of which only
  // the parameters are read: no covariance and no CF trace, and the fit with held directions
  // starts from the fit without them moved onto the hold (ModelFitOptions::
  // held_fit_from_projection).
  bool judgement_fit = false;
};

// A method's fit: the generic Ceres fit's result shape (NLopt methods leave the covariance out and
// say so in covariance_message), the objective evaluations over all training runs (Ceres: residual
// + Jacobian evaluations), what was minimised in words, and the best CF vs evaluations.
struct ModelFitMethodOutcome {
  ModelFitResult fit;
  int evaluations = 0;
  std::string objective;
  std::vector<ConvergencePoint> trace;
};

struct FitMethod {
  std::string name;
  std::string description;
  std::function<ModelFitMethodOutcome(const std::vector<AlignedRun>&, const RobotModelInterface&,
                                      const FitMethodSettings&)>
      run_model;
};

const std::vector<FitMethod>& FitMethods();
const FitMethod* FindFitMethod(const std::string& name);  // nullptr if unknown
std::string FitMethodNames();                             // "ceres, ceres-dogleg, crs2lm, ..."
// Ceres methods (ceres, ceres-dogleg) start where they are told and fit tracks; NLopt's search
// their box.
bool IsCeresMethod(const std::string& name);

// --residuals auto (fit/residual_choice.h): kTrack when the training runs' ground truth is a dense
// track and `method` is a Ceres one, kFinalPose otherwise; nothing without residuals_auto.
// tracks[i] is training[i]'s ground truth.
void ResolveAutoResiduals(const std::vector<AlignedRun>& training,
                          const std::vector<const GroundTruthTrack*>& tracks,
                          const std::string& method, FitMethodSettings* settings);

}  // namespace fitcal
