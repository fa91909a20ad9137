#include "calibrate/outcome_figures.h"

#include <algorithm>
#include <cmath>

namespace fitcal {

std::vector<CfRow> CfRows(const RobotModelInterface& model, const CalibrationOutcome& o,
                          int threads) {
  const CandidateErrors errors(model, threads);
  const auto row = [&](const char* side, const std::vector<AlignedRun>& runs) {
    return CfRow{side, errors(o.candidates[0], runs), errors(o.selected(), runs)};
  };
  std::vector<CfRow> rows = {row("training", o.split.training)};
  if (!o.split.validation.empty()) rows.push_back(row("validation", o.split.validation));
  return rows;
}

OutcomeEverydayDriving CompareOutcomeEverydayDriving(const RobotModelInterface& model,
                                                     const CalibrationOutcome& o, int threads) {
  const bool held_out = !o.split.validation.empty();
  const std::vector<AlignedRun>& runs = held_out ? o.split.validation : o.split.training;
  return {held_out, CompareEverydayDriving(model, o.candidates[0], o.selected(), runs,
                                           TracksOf(runs), threads)};
}

ClockOffsetSummary SummariseClockOffsets(const ModelFitResult& fit, const TrackFitData& track) {
  ClockOffsetSummary s;
  const std::size_t n = track.clock_groups.size();
  const double bound = kMaxClockOffsetS;
  for (std::size_t g = 0; g < n; ++g) {
    s.sigma_s.push_back(g < fit.clock_offset_sigma_s.size() ? fit.clock_offset_sigma_s[g] : 0.0);
    s.mean_sigma_s += s.sigma_s.back() / n;
    if (std::abs(fit.clock_offsets_s[g]) < bound * (1.0 - 1e-3)) continue;
    if (++s.num_on_bound <= 3) {
      s.first_on_bound += (s.first_on_bound.empty() ? "" : ", ") + track.clock_groups[g];
    }
  }
  if (n == 0) return s;
  std::vector<double> sorted(fit.clock_offsets_s.begin(), fit.clock_offsets_s.begin() + n);
  std::sort(sorted.begin(), sorted.end());
  s.median_s = sorted[n / 2];
  s.lo_s = sorted.front();
  s.hi_s = sorted.back();
  return s;
}

std::vector<OutlierRun> OutlierTrainingRuns(const RobotModelInterface& model,
                                            const RunSplit& split, const ModelFitResult& fit,
                                            int threads) {
  if (!fit.HasFinitePoint()) return {};
  std::vector<std::string> ids;
  for (const AlignedRun& run : split.training) ids.push_back(run.id);
  const FinalPoseErrors errors =
      EvaluateFinalPoseErrors(model, fit.parameters, split.training, threads);
  return FindOutlierRuns(ids, errors.per_run_cf);
}

DroppedGlitches CountDroppedGlitches(const std::vector<RunLog>& runs) {
  DroppedGlitches g;
  for (const RunLog& run : runs) {
    g.intervals += run.encoders.dropped_glitches;
    g.runs += run.encoders.dropped_glitches > 0;
  }
  return g;
}

}  // namespace fitcal
