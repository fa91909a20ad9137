#include "validation/held_out_halves.h"

#include <algorithm>
#include <cstdio>
#include <unordered_map>
#include <utility>

#include "validation/time_blocks.h"

namespace fitcal {

HalvesFold TimeBlockFold(const RunSplit& whole, const std::vector<RunLog>& logs, int num_blocks,
                         int fold) {
  std::unordered_map<std::string, const RunLog*> log_of;
  for (const RunLog& log : logs) log_of[log.id] = &log;
  HalvesFold blocks;
  blocks.logs = logs;
  // The logs grow below; `log_of` points into the caller's, which stay put.
  for (const AlignedRun& run : whole.training) {
    const RunLog& log = *log_of.at(run.id);
    for (AlignedRun& block : CutIntoTimeBlocks(run, log.ground_truth, num_blocks)) {
      // A block replays against its run's track, found under the block's own id.
      blocks.logs.push_back(log);
      blocks.logs.back().id = block.id;
      const bool trains = (block.repetition % 2) == (fold == 0 ? 1 : 0);
      (trains ? blocks.split.training : blocks.split.validation).push_back(std::move(block));
    }
  }
  return blocks;
}

RunSplit RunsFold(const RunSplit& whole, int fold) {
  RunSplit half;
  for (std::size_t i = 0; i < whole.training.size(); ++i) {
    (static_cast<int>(i % 2) == fold ? half.training : half.validation)
        .push_back(whole.training[i]);
  }
  return half;
}

HalvesJudgement JudgeOnHeldOutHalves(const RunSplit& split, const std::vector<RunLog>& logs,
                                     ResidualKind residuals, int num_blocks,
                                     const std::vector<double>& nominal, const FitOnFold& fit_on,
                                     const CfOnRuns& cf) {
  HalvesJudgement j;
  if (!split.validation.empty() || split.training.empty()) return j;
  j.by_time = split.training.size() <= kMaxRunsForTimeBlocks;
  if (j.by_time && residuals == ResidualKind::kFinalPose) return j;
  double nominal_sum = 0.0, calibrated_sum = 0.0;
  std::size_t held_out = 0;
  for (int fold = 0; fold < 2; ++fold) {
    const HalvesFold half = j.by_time ? TimeBlockFold(split, logs, num_blocks, fold)
                                      : HalvesFold{RunsFold(split, fold), logs};
    if (half.split.training.empty() || half.split.validation.empty()) return j;
    const std::optional<std::vector<double>> fitted = fit_on(half);
    if (!fitted) return j;
    // Each held-out run weighs alike across the folds: the folds' means weighted by their runs.
    const double n = static_cast<double>(half.split.validation.size());
    nominal_sum += n * cf(nominal, half.split.validation);
    calibrated_sum += n * cf(*fitted, half.split.validation);
    held_out += half.split.validation.size();
  }
  j.judged = held_out > 0;
  j.nominal_cf = nominal_sum / std::max<std::size_t>(1, held_out);
  j.calibrated_cf = calibrated_sum / std::max<std::size_t>(1, held_out);
  return j;
}

std::string HalvesDescription(const HalvesJudgement& j, int num_blocks) {
  char cf[64];
  std::snprintf(cf, sizeof(cf), "CF %.4f -> %.4f", j.nominal_cf, j.calibrated_cf);
  return j.by_time ? "held-out time blocks of the training runs (two folds of " +
                         std::to_string(num_blocks) + " blocks of equal path, odd against even; " +
                         cf + ")"
                   : "held-out halves of the training runs (two folds, every other run against "
                     "the rest; " +
                         std::string(cf) + ")";
}

}  // namespace fitcal
