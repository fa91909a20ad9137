#include "validation/held_out_halves.h"

#include <algorithm>
#include <set>
#include <utility>

#include "odometry/text_format.h"
#include "validation/time_blocks.h"

namespace fitcal {

HalvesFold TimeBlockFold(const RunSplit& whole, int num_blocks, int fold) {
  HalvesFold blocks;
  for (const AlignedRun& run : whole.training) {
    for (AlignedRun& block : CutIntoTimeBlocks(run, num_blocks)) {
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

std::vector<int> TimeBlockCounts(int num_blocks) {
  std::set<int> counts = {2, 4, 8};
  counts.insert(num_blocks);
  return {counts.begin(), counts.end()};
}

bool HalvesGroup::Beats() const {
  return calibrated_cf < nominal_cf &&
         std::none_of(never_worse.begin(), never_worse.end(),
                      [](const NeverWorseJudgement& n) { return n.Refuses(); });
}

bool HalvesJudgement::Beats() const {
  int beat = 0;
  for (const HalvesGroup& g : groups) beat += g.Beats() ? 1 : 0;
  return judged && 2 * beat > static_cast<int>(groups.size());
}

namespace {

// Appends the per-run values of `part` (the metrics of one fold's held-out runs) to `all`.
void AppendRuns(const EverydayDrivingMetrics& part, EverydayDrivingMetrics* all) {
  all->runs += part.runs;
  all->per_run_cf.insert(all->per_run_cf.end(), part.per_run_cf.begin(), part.per_run_cf.end());
  all->per_run_ate_m.insert(all->per_run_ate_m.end(), part.per_run_ate_m.begin(),
                            part.per_run_ate_m.end());
  if (all->drift.empty()) {
    for (const DriftAtLength& d : part.drift) all->drift.push_back({d.length_m});
  }
  for (std::size_t k = 0; k < part.drift.size() && k < all->drift.size(); ++k) {
    const DriftAtLength& d = part.drift[k];
    DriftAtLength& a = all->drift[k];
    a.windows += d.windows;
    a.per_run_translation_percent.insert(a.per_run_translation_percent.end(),
                                         d.per_run_translation_percent.begin(),
                                         d.per_run_translation_percent.end());
    a.per_run_windows.insert(a.per_run_windows.end(), d.per_run_windows.begin(),
                             d.per_run_windows.end());
  }
}

// The folds judged: the two halves of the runs, or the two of each block count.
std::vector<HalvesFold> Folds(const RunSplit& split, const std::vector<int>& block_counts) {
  std::vector<HalvesFold> folds;
  for (int fold = 0; fold < 2; ++fold) {
    if (block_counts.empty()) folds.push_back({RunsFold(split, fold)});
  }
  for (int count : block_counts) {
    for (int fold = 0; fold < 2; ++fold) {
      folds.push_back(TimeBlockFold(split, count, fold));
      // Blocks of one count repeat one another (their scatter is the noise of a block); blocks
      // of another length do not: the label carries the count, the family stays the run's.
      for (AlignedRun& block : folds.back().split.validation) {
        block.trajectory += " (" + std::to_string(count) + " blocks)";
      }
    }
  }
  return folds;
}

double MeanOf(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

}  // namespace

HalvesJudgement JudgeOnHeldOutHalves(const RunSplit& split, ResidualKind residuals,
                                     int num_blocks,
                                     const std::vector<double>& nominal, const FitOnFold& fit_on,
                                     const MetricsOnFold& score) {
  HalvesJudgement j;
  if (!split.validation.empty() || split.training.empty()) return j;
  j.by_time = split.training.size() <= kMaxRunsForTimeBlocks;
  if (j.by_time && residuals == ResidualKind::kFinalPose) return j;
  // One group of folds per block count (one group, the halves of the runs, otherwise).
  std::vector<std::vector<int>> groups = {{}};
  if (j.by_time) {
    j.block_counts = TimeBlockCounts(num_blocks);
    groups.clear();
    for (int count : j.block_counts) groups.push_back({count});
  }
  for (const std::vector<int>& group : groups) {
    EverydayDrivingMetrics nominal_all, calibrated_all;
    std::vector<AlignedRun> held_out;
    for (const HalvesFold& half : Folds(split, group)) {
      if (half.split.training.empty() || half.split.validation.empty()) return j;
      const std::optional<std::vector<double>> fitted = fit_on(half);
      if (!fitted) return j;
      AppendRuns(score(nominal, half), &nominal_all);
      AppendRuns(score(*fitted, half), &calibrated_all);
      held_out.insert(held_out.end(), half.split.validation.begin(), half.split.validation.end());
    }
    HalvesGroup g;
    g.block_count = group.empty() ? 0 : group.front();
    g.nominal_cf = MeanOf(nominal_all.per_run_cf);
    g.calibrated_cf = MeanOf(calibrated_all.per_run_cf);
    g.never_worse = JudgeNeverWorse(held_out, nominal_all, calibrated_all);
    j.groups.push_back(std::move(g));
  }
  j.judged = true;
  // The counts weigh alike: the mean of their means.
  for (const HalvesGroup& g : j.groups) {
    j.nominal_cf += g.nominal_cf / static_cast<double>(j.groups.size());
    j.calibrated_cf += g.calibrated_cf / static_cast<double>(j.groups.size());
  }
  return j;
}

std::string HalvesDescription(const HalvesJudgement& j) {
  const std::string cf = StrFormat("CF %.4f -> %.4f", j.nominal_cf, j.calibrated_cf);
  if (!j.by_time) {
    return "held-out halves of the training runs (two folds, every other run against the rest; " +
           cf + ")";
  }
  std::string counts;
  for (int c : j.block_counts) counts += (counts.empty() ? "" : ", ") + std::to_string(c);
  int beat = 0;
  for (const HalvesGroup& g : j.groups) beat += g.Beats() ? 1 : 0;
  return "held-out time blocks of the training runs (two folds each of " + counts +
         " blocks of equal path, odd against even; the fits beat the nominal for " +
         std::to_string(beat) + " of " + std::to_string(j.groups.size()) +
         " counts; mean over the counts " + cf + ")";
}

}  // namespace fitcal
