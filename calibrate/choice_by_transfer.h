#pragma once
// The fit's choices made by transfer, each fold fitted by the request's method: the residual kind
// (validation/residual_kind_transfer.h), the track's heading and, on the held-out runs, its
// weights (validation/track_objective_transfer.h), and, with nothing held out, the two-fold
// judgement of the method (validation/held_out_halves.h).

#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "calibrate/fit_methods.h"
#include "fit/run_split.h"
#include "validation/held_out_halves.h"
#include "validation/residual_kind_transfer.h"

namespace fitcal {

// How the choices by transfer and the held-out halves score a fit: the everyday-driving
// measures (Eq. 14 CF, drift per each of `lengths_m`, ATE) of parameters `p` on runs, each
// against its track. The choices by transfer read the drift per kTransferDriftLength_m only.
ScoreOnRuns EverydayDrivingScore(const RobotModelInterface& model, int threads,
                                 std::vector<double> lengths_m);

// The fits of the folds the choices by transfer make (residual kind, then track objective), each
// made once: the track with the default objective on a fold is a candidate of both.
class FoldFits {
 public:
  // `s` fitted on `training` from `start` (the fit of all the training runs), its weights seeded
  // by that fit's noise levels when it estimated them; nullopt when not usable.
  std::optional<std::vector<double>> Fit(const FitMethod& method, const RobotModelInterface& model,
                                         FitMethodSettings s,
                                         const std::vector<AlignedRun>& training);

  // `score`, each fit scored once on each set of runs: the two choices judge the default
  // candidate's fits (one fit per fold, above) on the same runs, and the score is a function of
  // the parameters and the runs alone.
  ScoreOnRuns ScoredOnce(ScoreOnRuns score);

  std::vector<double> start;  // empty: the nominal
  NoiseLevels seed_levels;

 private:
  std::mutex mutex_;
  std::map<std::string, std::optional<std::vector<double>>> done_;
  std::map<std::string, EverydayDrivingMetrics> scored_;
};

// --residuals auto proposing the track: the track and the final pose are fitted and judged on
// kinds of run they were not fitted on (validation/residual_kind_transfer.h); the final pose
// replaces the track when that judgement says so (settings and *track_data follow). The folds'
// fits start from the track fit of all the training runs (`full`, the fit the command writes
// when the track stays), so each ends in a few steps, and run in parallel. The lines for the
// terminal; none when nothing could be judged.
std::vector<std::string> ChooseResidualsByTransfer(const FitMethod& method, int threads,
                                                   const RobotModelInterface& model,
                                                   const RunSplit& split,
                                                   FitMethodSettings* settings,
                                                   std::optional<TrackFitData>* track_data,
                                                   std::optional<ModelFitMethodOutcome>* full,
                                                   FoldFits* fold_fits);

// An explicit --residuals final-pose fitted by a Ceres method on training runs whose ground truth
// is a dense track: the final pose's fit from the guess and from the track's fit of the same runs,
// the lower cost kept, as a final pose chosen by transfer is fitted. From the guess alone a fit
// far from the truth can end in a local minimum of the final poses that holds its flat direction,
// so no reason to start across the box shows (a diff drive with a radius guessed 24 % off, its
// runs cut to 56 %: radii 0.0445 / 0.0276 m against 0.0319 / 0.0449, exit 0). nullopt where this
// does not apply (another kind, another method, sparse ground truth, a start given): the fit
// from the guess is the caller's.
std::optional<ModelFitMethodOutcome> FitAskedFinalPoseFromTheTrackToo(
    const FitMethod& method, const RobotModelInterface& model,
    const std::vector<AlignedRun>& training, const FitMethodSettings& settings);

// --track-heading auto on track residuals: the candidates fitted and judged by
// transfer (validation/track_objective_transfer.h), each fold's fit started from the fit of all
// the training runs when the residual choice made one; settings, *track_data and *full follow the
// choice. The lines for the terminal, and in *note what the calibration's objective records.
std::vector<std::string> ChooseTrackObjectiveByTransfer(
    const FitMethod& method, int threads, const RobotModelInterface& model, const RunSplit& split,
    FitMethodSettings* settings, std::optional<TrackFitData>* track_data,
    std::optional<ModelFitMethodOutcome>* full, FoldFits* fold_fits, std::string* note);

// --weights auto on track residuals: the fit with weights estimated from the data
// (fit/noise_levels.h), started from the fixed weights' fit of all the training runs (*full, made
// here unless a choice before made it), replaces it when lower on the held-out runs in CF, drift
// and ATE (validation/track_objective_transfer.h); settings and *full follow the choice. Without
// held-out runs the weights stay fixed, said in one line. The lines for the terminal, and in
// *note (appended) what the calibration's objective records.
std::vector<std::string> ChooseWeightsOnHeldOutRuns(const FitMethod& method, int threads,
                                                    const RobotModelInterface& model,
                                                    const RunSplit& split,
                                                    FitMethodSettings* settings,
                                                    std::optional<ModelFitMethodOutcome>* full,
                                                    std::string* note);

// With nothing held out, the two-fold judgement of validation/held_out_halves.h, each fold fitted
// by `method` with the whole data's settings and scored on the everyday-driving measures. A fold
// is fitted from the guess and from `whole_fit` (the fit of all the training runs; empty: the
// guess only), the lower cost on the fold's own runs kept: judged is the best fit the fold's runs
// give, not where one start of the search ended.
HalvesJudgement JudgeMethodOnHeldOutHalves(const FitMethod& method, int threads, int time_blocks,
                                           const FitMethodSettings& settings,
                                           const std::vector<double>& whole_fit,
                                           const RobotModelInterface& model,
                                           const RunSplit& split);

}  // namespace fitcal
