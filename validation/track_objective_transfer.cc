#include "validation/track_objective_transfer.h"

#include "odometry/text_format.h"

namespace fitcal {
namespace {

// Every fold's measures pooled: runs and windows weigh alike across folds.
PooledTransfer Pool(const std::vector<std::vector<EverydayDrivingMetrics>>& scores, int candidate) {
  PooledTransfer p;
  double drift_sum = 0.0;
  for (const std::vector<EverydayDrivingMetrics>& fold : scores) {
    const EverydayDrivingMetrics& m = fold[candidate];
    p.runs += m.runs;
    p.cf += m.cf * m.runs;
    p.ate_rmse_m += m.mean_ate_rmse_m * m.runs;
    if (const DriftAtLength* d = DriftAt(m, kTransferDriftLength_m)) {
      p.drift_windows += d->windows;
      drift_sum += d->translation_percent * d->windows;
    }
  }
  if (p.runs > 0) {
    p.cf /= p.runs;
    p.ate_rmse_m /= p.runs;
  }
  if (p.drift_windows > 0) p.drift_percent = drift_sum / p.drift_windows;
  return p;
}

// Lower on every pooled measure (drift only where both have windows).
bool BetterOnEveryMeasure(const PooledTransfer& a, const PooledTransfer& b) {
  const bool drift = a.drift_windows == 0 || b.drift_windows == 0 ||
                     a.drift_percent < b.drift_percent;
  return a.cf < b.cf && a.ate_rmse_m < b.ate_rmse_m && drift;
}

// The rule of the header on `folds`: every candidate fitted on each fold's training runs, scored
// on its judged runs, pooled.
TrackObjectiveJudgement JudgeOnFolds(const std::vector<TrackObjective>& candidates,
                                     const TransferFolds& folds,
                                     const FitByTrackObjective& fit_on, const ScoreOnRuns& score) {
  TrackObjectiveJudgement j;
  j.candidates = candidates;
  if (candidates.size() < 2 || folds.folds.empty()) return j;
  const FitCandidate fit_candidate = [&](int c, const std::vector<AlignedRun>& training) {
    return fit_on(candidates[c], training);
  };
  const auto scores = FitAndScoreFolds(folds.folds, static_cast<int>(candidates.size()),
                                       fit_candidate, score);
  if (!scores) return j;
  j.judged = true;
  j.on_free_driving = folds.on_free_driving;
  for (const TransferFold& f : folds.folds) {
    j.judged_on += (j.judged_on.empty() ? "" : ", ") + f.judged_on + " (" +
                   std::to_string(f.judged.size()) + ")";
  }
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    j.pooled.push_back(Pool(*scores, static_cast<int>(c)));
  }
  for (std::size_t c = 1; c < candidates.size(); ++c) {
    if (!BetterOnEveryMeasure(j.pooled[c], j.pooled[0])) continue;
    if (j.chosen == 0 || j.pooled[c].cf < j.pooled[j.chosen].cf) j.chosen = static_cast<int>(c);
  }
  return j;
}

// "by transfer (pooled over circular (44), square (33)" or "on the held-out runs (20"
std::string WhereJudged(const TrackObjectiveJudgement& j) {
  if (j.on_held_out_runs) return "on the held-out runs (" + std::to_string(j.pooled[0].runs);
  return "by transfer (pooled over " + j.judged_on;
}

}  // namespace

std::string ToString(const TrackObjective& objective) {
  return std::string("weights ") + (objective.estimate_weights ? "estimated" : "fixed") +
         ", heading " + ToString(objective.heading);
}

TrackObjectiveJudgement JudgeTrackObjectivesByTransfer(
    const std::vector<TrackObjective>& candidates, const RunSplit& split,
    const FitByTrackObjective& fit_on, const ScoreOnRuns& score) {
  return JudgeOnFolds(candidates, MakeTransferFolds(split), fit_on, score);
}

TrackObjectiveJudgement JudgeTrackWeightsOnHeldOutRuns(
    const std::vector<TrackObjective>& candidates, const RunSplit& split,
    const FitByTrackObjective& fit_on, const ScoreOnRuns& score) {
  TransferFolds held_out;
  if (!split.validation.empty()) {
    held_out.folds.push_back({"held-out", "every training run", split.training, split.validation});
  }
  TrackObjectiveJudgement j = JudgeOnFolds(candidates, held_out, fit_on, score);
  j.on_held_out_runs = true;
  return j;
}

std::string TrackObjectiveChoiceText(const TrackObjectiveJudgement& j) {
  if (!j.judged) return "";
  const PooledTransfer& d = j.pooled[0];
  const PooledTransfer& c = j.pooled[j.chosen];
  if (j.chosen == 0) {
    return StrFormat("; %s kept %s: CF %.4f, drift 2 m %.3f %%, ATE %.4f m; no other lower on "
                     "all three)",
                     ToString(j.candidates[0]).c_str(), WhereJudged(j).c_str(), d.cf,
                     d.drift_percent, d.ate_rmse_m);
  }
  return StrFormat("; %s chosen %s: CF %.4f -> %.4f, drift 2 m %.3f -> %.3f %%, ATE %.4f -> "
                   "%.4f m against the default)",
                   ToString(j.candidates[j.chosen]).c_str(), WhereJudged(j).c_str(), d.cf, c.cf,
                   d.drift_percent, c.drift_percent, d.ate_rmse_m, c.ate_rmse_m);
}

std::vector<std::string> TrackObjectiveJudgementLines(const TrackObjectiveJudgement& j) {
  std::vector<std::string> lines;
  if (!j.judged) return lines;
  lines.push_back(j.on_held_out_runs
                      ? StrFormat("track weights fitted on every training run, judged on the "
                                  "held-out runs (%d):",
                                  j.pooled[0].runs)
                      : StrFormat("track objectives judged on runs of a kind they were not "
                                  "fitted on, pooled over %s:",
                                  j.judged_on.c_str()));
  lines.push_back(StrFormat("  %-44s %10s %16s %14s", "weights, heading", "CF", "drift 2 m [%]",
                            "ATE RMSE [m]"));
  for (std::size_t c = 0; c < j.candidates.size(); ++c) {
    const PooledTransfer& p = j.pooled[c];
    const std::string name = ToString(j.candidates[c]) + (c == 0 ? " (default)" : "");
    lines.push_back(StrFormat("  %-44s %10.4f %16.3f %14.4f", name.c_str(), p.cf, p.drift_percent,
                              p.ate_rmse_m));
  }
  if (j.chosen == 0) {
    lines.push_back(StrFormat("  %s kept: no other is lower on all three (pooled CF, drift, ATE)",
                              ToString(j.candidates[0]).c_str()));
  } else {
    lines.push_back(StrFormat("  %s chosen: lower than the default on all three (pooled CF, "
                              "drift, ATE), and the lowest CF of those that are",
                              ToString(j.candidates[j.chosen]).c_str()));
  }
  return lines;
}

}  // namespace fitcal
