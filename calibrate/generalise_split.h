#pragma once
// One split of `generalise` (validation/generalisation.h) calibrated as `fit --residuals
// final-pose` calibrates (the table's "fit" is a final-pose fit; on dense tracks `fit`'s default
// fits the track): the split's training runs fitted by Calibrate (calibrate/calibrate.h; Ceres, no
// record), its candidates judged by the same result gate, never-worse rule and bound check on the
// split's held-out runs, and every candidate of the table scored on them with that same fit. The
// table's scores stay blind (nothing is selected on the runs that score it); the decision says
// what `fit` would write, or why it would refuse, on that split.

#include <optional>
#include <string>
#include <vector>

#include "calibrate/calibrate.h"
#include "fit/segment_cost.h"
#include "validation/generalisation.h"

namespace fitcal {

struct SplitCalibration {
  SplitScores scores;
  CalibrationOutcome outcome;  // the gate's decision on the split, as `fit` decides it
};

// `logs[i]` is the run `runs[i]` was aligned from. The fit's settings are `options`' threads with
// fit's defaults (Ceres Levenberg-Marquardt, final poses); no channel-order check (the data set's
// wiring does not change between splits; `fit` checks it).
SplitCalibration CalibrateSplit(const RobotModelInterface& model, const std::vector<RunLog>& logs,
                                const std::vector<AlignedRun>& runs,
                                const GeneralisationSplit& split, const ModelFitOptions& options,
                                const TrackCandidates& track_candidates,
                                const ParameterTying& tying);

// The decision in one line: "writes <candidate> (held-out CF <nominal> -> <selected>)" or
// "refuses (exit <code>): <reasons>"; the method's fit is named "fit" as in the table.
std::string DecisionLine(const CalibrationOutcome& outcome);

// Over the folds of leave-one-session-out: "fit --residuals final-pose on the M folds: refuses
// (exit 5) K, writes fit N, ..." (each decision and how often, sorted).
std::string FoldDecisionsLine(const std::vector<SplitCalibration>& folds);

// OptiOdom's checkpoints (every 0.5 m of path, as Sousa et al.) for every run (`--optiodom`), or
// nothing when some run's ground truth holds no pose between its start and end (their cost needs
// the track). runs = AlignRuns(logs), in the same order.
std::optional<std::vector<std::vector<Segment>>> OptiOdomCheckpoints(
    const std::vector<AlignedRun>& runs, const std::vector<RunLog>& logs);

}  // namespace fitcal
