#pragma once
// With nothing held out (every run trains: `fit --train-reps 1-99`, or a data set of free
// driving), the calibration procedure is judged by two folds before the fit of all the training
// runs is written: a fit of one half is judged on the other half and back, against the nominal
// (two-fold cross-validation).
// - More than two runs: every other run trains, the rest is held out.
// - One or two long runs fitted on their tracks (--residuals track/both, or auto resolving to
//   track): each is cut into blocks of equal ground-truth path (validation/time_blocks.h), odd
//   blocks against even ones, for 2, 4 and 8 blocks (and `num_blocks` when it is another count),
//   and the fits must beat the nominal for most of the counts: with one count the verdict flipped
//   with the count on data that calibrate (issue 39: 4 refused, 2 and 8 wrote). One
//   or two runs fitted on their final poses are not judged: the blocks were measured for track
//   fits only.
// The fits beat the nominal when their mean CF on the held-out halves is lower and no measure
// (CF, ATE, drift per length; on all halves and per family) is worse than the nominal's beyond
// the scatter between the repetitions - the blocks of one count, the runs of one label
// (validation/never_worse.h).
// The calibration written is the fit of everything, which was measured to transfer better than a
// fit of half of it (docs/everyday_driving.md); the judgement says whether the runs determine the
// parameters at all, and the caller writes nothing when the halves do not beat the nominal.
// Like validation/residual_kind_transfer.h, the judgement is a policy over fits the caller makes
// (`fit_on`) and scores it computes (`cf`): any model, any fitter.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fit/model_fit.h"
#include "fit/run_split.h"
#include "validation/everyday_driving.h"
#include "validation/never_worse.h"

namespace fitcal {

// Up to this many training runs are cut into time blocks; more are halved.
constexpr std::size_t kMaxRunsForTimeBlocks = 2;

// One fold: the runs it trains on and is judged on (each carries its ground-truth track).
struct HalvesFold {
  RunSplit split;
};

// The time blocks of the training runs, fold 0 training on the odd blocks and fold 1 on the even.
HalvesFold TimeBlockFold(const RunSplit& whole, int num_blocks, int fold);

// Every other training run (in data-set order, so each session gives to both halves): fold 0
// trains on runs 0, 2, 4, ..., fold 1 on runs 1, 3, 5, ...
RunSplit RunsFold(const RunSplit& whole, int fold);

// The parameters fitted on a fold's training runs; nullopt when that fit cannot be made or is not
// usable (the judgement is then not made).
using FitOnFold = std::function<std::optional<std::vector<double>>(const HalvesFold& fold)>;
// Parameters replayed on a fold's held-out runs (against their tracks): per-run CF (Palacin
// Eq. 14), ATE and drift (validation/everyday_driving.h) in the order of fold.split.validation.
using MetricsOnFold = std::function<EverydayDrivingMetrics(const std::vector<double>& parameters,
                                                           const HalvesFold& fold)>;

// The block counts judged for `num_blocks` (--time-blocks): 2, 4, 8 and num_blocks, sorted.
std::vector<int> TimeBlockCounts(int num_blocks);

// The folds of one block count (0: the halves of the runs): their held-out runs pooled.
struct HalvesGroup {
  int block_count = 0;
  double nominal_cf = 0.0;     // mean CF (Eq. 14) of the held-out runs of both folds
  double calibrated_cf = 0.0;  // of each fold's fit on its held-out half
  std::vector<NeverWorseJudgement> never_worse;  // every measure on the pooled halves
  // Lower mean CF, and no measure worse beyond the scatter (validation/never_worse.h).
  bool Beats() const;
};

struct HalvesJudgement {
  bool judged = false;
  bool by_time = false;           // time blocks of one or two runs (else halves of the runs)
  std::vector<int> block_counts;  // by_time: the counts judged
  std::vector<HalvesGroup> groups;  // one per block count; one for the halves of the runs
  double nominal_cf = 0.0;        // the mean over the groups of their CFs
  double calibrated_cf = 0.0;
  // The fits beat the nominal in more than half of the groups (the one group of halves of runs;
  // two of the three block counts 2, 4, 8).
  bool Beats() const;
};

// Not judged when runs are held out (the gate judges on them), when nothing trains, when one or
// two runs are fitted on their final poses, or when a fold is empty or its fit fails. `residuals`
// is the kind the whole data is fitted with (auto already resolved); `nominal` the model's nominal
// parameters. The CFs are means over the held-out runs of every fold, each run weighing alike.
HalvesJudgement JudgeOnHeldOutHalves(const RunSplit& split, ResidualKind residuals,
                                     int num_blocks,
                                     const std::vector<double>& nominal, const FitOnFold& fit_on,
                                     const MetricsOnFold& score);

// What the halves were, for the terminal and the calibration file's selected_on.
std::string HalvesDescription(const HalvesJudgement& j);

}  // namespace fitcal
