#pragma once
// `fit --track-heading auto` / `--weights auto`: how the track residual weighs its checkpoints.
// The candidates are the track objectives the flags allow - heading from the run's start or as
// increments (fit/track_residual.h), weights fixed (1 m : 1 rad, Eq. 14) or estimated from the fit
// (fit/noise_levels.h) - the first of them the default. The heading is judged by transfer as the
// residual kind is (validation/residual_kind_transfer.h, same folds: held-out free driving, else
// leave one kind of training run out); the weights on the held-out runs (below).
//
// Rule: every held-out run counts once, whatever kind it is: the CF and the ATE pooled as means
// over all the judged runs, the drift per 2 m as the mean over all the judged windows. A candidate
// replaces the default only when it is lower on all three pooled measures (it never trades one
// measure for another); of several, the one with the lowest pooled CF. Pooling rather than
// counting wins per kind (the residual kind's rule): the candidates differ by a weight, not by
// what is compared, and their differences are small against the difference between kinds of
// loop, so a per-kind vote mostly says which kind of loop is larger. Chosen on the training runs
// only, never on the free runs that judge a calibration (docs/everyday_driving.md).

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fit/run_split.h"
#include "fit/track_residual.h"
#include "validation/residual_kind_transfer.h"

namespace fitcal {

struct TrackObjective {
  bool estimate_weights = false;  // noise levels from the fit (fit/noise_levels.h), else fixed
  TrackHeading heading = TrackHeading::kFromStart;
};
// "weights fixed, heading from-start"
std::string ToString(const TrackObjective& objective);

// The parameters `objective` gives when fitted on `training`; nullopt when that fit is not usable.
using FitByTrackObjective = std::function<std::optional<std::vector<double>>(
    const TrackObjective& objective, const std::vector<AlignedRun>& training)>;

// A candidate's measures pooled over every judged run.
struct PooledTransfer {
  int runs = 0;
  double cf = 0.0;               // mean per-run Eq. 14 over all judged runs
  int drift_windows = 0;         // windows of kTransferDriftLength_m
  double drift_percent = 0.0;    // their mean translation error
  double ate_rmse_m = 0.0;       // mean per-run ATE RMSE
};

struct TrackObjectiveJudgement {
  bool judged = false;
  bool on_free_driving = false;
  bool on_held_out_runs = false;  // JudgeTrackWeightsOnHeldOutRuns
  std::vector<TrackObjective> candidates;  // [0] the default
  std::vector<PooledTransfer> pooled;      // per candidate
  std::string judged_on;                   // the folds in words: "circular (44), square (33)"
  int chosen = 0;
};

// Not judged (chosen = 0) with one candidate, nothing to judge on, or a fit not usable.
TrackObjectiveJudgement JudgeTrackObjectivesByTransfer(
    const std::vector<TrackObjective>& candidates, const RunSplit& split,
    const FitByTrackObjective& fit_on, const ScoreOnRuns& score);

// --weights auto: the weights judged by the same rule on the held-out runs (the gate's: held-out
// repetitions, free runs) of the candidates fitted on every training run. Not by transfer between
// kinds of loop: the weights model the noise of these runs' ground truth and odometry, which a
// fit on circles judged on squares confounds with what circles cannot determine (on the real
// loops the transfer folds rejected estimated weights that the held-out repetitions and the free
// runs preferred, docs/everyday_driving.md). Not judged without held-out runs.
TrackObjectiveJudgement JudgeTrackWeightsOnHeldOutRuns(
    const std::vector<TrackObjective>& candidates, const RunSplit& split,
    const FitByTrackObjective& fit_on, const ScoreOnRuns& score);

// What the calibration's objective records of the choice: "; weights fixed, heading increments
// chosen by transfer (pooled over circular (44), square (33): CF 0.0521 -> 0.0513, ...)"; the
// default "kept by transfer (pooled over ...: CF 0.1545, ...)"; empty when not judged.
std::string TrackObjectiveChoiceText(const TrackObjectiveJudgement& judgement);

// The table and the verdict with its reason, one line each; none when not judged.
std::vector<std::string> TrackObjectiveJudgementLines(const TrackObjectiveJudgement& judgement);

}  // namespace fitcal
