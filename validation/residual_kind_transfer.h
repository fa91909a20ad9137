#pragma once
// `fit --residuals auto`: which residual kind transfers, judged on kinds of run the fits did not
// see (issue 29 item 4). The auto rule (fit/residual_choice.h) proposes the track wherever the
// ground truth is dense; the final pose (Palacin Eq. 14) is the alternative. Each kind is fitted
// and judged on runs of a kind it was not fitted on, on the final-pose CF and on everyday driving
// (drift per 2 m, ATE RMSE; validation/everyday_driving.h):
//   - held-out free driving (trajectory family "free") present: both kinds fitted on all the
//     training runs and judged on it - free driving is the judge that counts, so the alternative
//     replaces the proposal when it is better on most of the three measures there;
//   - else training runs of two or more kinds (circles, squares, ...): leave one kind out - fitted
//     on the others, judged on it, for every kind. Closed loops were measured to be a weak judge
//     of what transfers to free driving (on the real OptiOdom robots circles against squares tied
//     between the two kinds while the free runs sided with the track, docs/everyday_driving.md),
//     so the alternative replaces the proposal only when it is better on every comparison.
// The choice is a policy over fits the caller makes (`fit_on`) and scores it computes (`score`):
// any model, any fitter. Every fit of every comparison runs at once, each on a thread of its own
// (`fit_on` must be safe to call concurrently); `fitcal fit` starts them from its fit of all the
// training runs (issue 40: the judgement cost 45 times the fit it selected when each fold was
// fitted from the nominal, one after the other).

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fit/model_fit.h"
#include "fit/run_split.h"
#include "odometry/aligned_run.h"
#include "validation/everyday_driving.h"

namespace fitcal {

// The parameters `kind` gives when fitted on `training`; nullopt when that fit is not usable.
using FitByKind = std::function<std::optional<std::vector<double>>(
    ResidualKind kind, const std::vector<AlignedRun>& training)>;
// Everyday-driving measures (CF, drift, ATE) of parameters on some runs.
using ScoreOnRuns = std::function<EverydayDrivingMetrics(const std::vector<double>& parameters,
                                                         const std::vector<AlignedRun>& runs)>;

// One comparison of candidate fits: the kind of run judged and the training runs the candidates
// are fitted on - held-out free driving (one fold: every training run, judged on the free runs),
// else one fold per kind of training run (fitted on the other kinds, judged on it).
struct TransferFold {
  std::string judged_on;  // the trajectory family judged on ("free", "circular", ...)
  std::string fitted_on;  // what the fits saw, in words
  std::vector<AlignedRun> training, judged;
};
struct TransferFolds {
  bool on_free_driving = false;
  std::vector<TransferFold> folds;  // empty: nothing to judge on
};
TransferFolds MakeTransferFolds(const RunSplit& split);

// Candidate `candidate` (0 .. n-1) fitted on `training`; nullopt when that fit is not usable.
using FitCandidate = std::function<std::optional<std::vector<double>>(
    int candidate, const std::vector<AlignedRun>& training)>;
// Every candidate fitted on every fold at once, each fit on a thread of its own (`fit_on` must be
// safe to call concurrently), then scored on the fold's judged runs: [fold][candidate]. Nullopt
// when some fit is not usable. Shared by every choice by transfer (residual kind, track
// objective: validation/track_objective_transfer.h).
std::optional<std::vector<std::vector<EverydayDrivingMetrics>>> FitAndScoreFolds(
    const std::vector<TransferFold>& folds, int candidates, const FitCandidate& fit_on,
    const ScoreOnRuns& score);

// The drift per `length_m` of `m` when it has windows there, else nullptr.
const DriftAtLength* DriftAt(const EverydayDrivingMetrics& m, double length_m);
// The everyday window judged between 1 and 5 m.
inline constexpr double kTransferDriftLength_m = 2.0;

// One kind of run judged: each residual kind's measures on it, fitted without it.
struct KindComparison {
  std::string judged_on;   // the trajectory family judged on ("free", "circular", ...)
  std::string fitted_on;   // what the fits saw, in words
  int runs = 0;
  EverydayDrivingMetrics proposed, alternative;
};

struct ResidualKindJudgement {
  bool judged = false;
  bool on_free_driving = false;
  ResidualKind proposed = ResidualKind::kTrack;
  ResidualKind alternative = ResidualKind::kFinalPose;
  ResidualKind chosen = ResidualKind::kTrack;
  std::vector<KindComparison> comparisons;
  int alternative_wins = 0;  // comparisons the alternative is better on
  int total = 0;             // comparisons made (a measure with no windows is not one)
};

// Not judged (chosen = proposed) when there is neither held-out free driving nor two kinds of
// training run, or when a fit is not usable.
ResidualKindJudgement JudgeResidualKindsByTransfer(ResidualKind proposed, ResidualKind alternative,
                                                   const RunSplit& split, const FitByKind& fit_on,
                                                   const ScoreOnRuns& score);

// The table and the verdict for the terminal, one line each.
std::vector<std::string> ResidualKindJudgementLines(const ResidualKindJudgement& judgement);

}  // namespace fitcal
