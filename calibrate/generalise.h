#pragma once
// What `generalise` computes and decides (the command loads, calls and prints): the candidates
// (validation/generalisation.h; OptiOdom's method, the track fit with effects, the track fit on
// dense ground-truth tracks as `fit --residuals auto` decides it), the table's splits and the
// folds of leave-one-session-out, the everyday driving of the fits and the summary of the folds.
// Each split is calibrated as `fit --residuals final-pose` calibrates it (the table's "fit" is a
// final-pose fit; on dense tracks `fit`'s default fits the track): its training runs fitted by
// Calibrate (calibrate/calibrate.h; Ceres, no record), its candidates judged by the same result
// gate, never-worse rule and bound check on its held-out runs, and every candidate of the table
// scored on them with that same fit. The table's scores stay blind (nothing is selected on the
// runs that score it); the decision says what `fit` would write, or why it would refuse.

#include <functional>
#include <string>
#include <vector>

#include "calibrate/calibrate.h"
#include "fit/segment_cost.h"
#include "validation/generalisation.h"
#include "validation/never_worse.h"

namespace fitcal {

struct SplitCalibration {
  SplitScores scores;
  CalibrationOutcome outcome;  // the gate's decision on the split, as `fit` decides it
};

// The decision in one line: "writes <candidate> (held-out CF <nominal> -> <selected>)" or
// "refuses (exit <code>): <reasons>"; the method's fit is named "fit" as in the table.
std::string DecisionLine(const CalibrationOutcome& outcome);

// Over the folds of leave-one-session-out: "fit --residuals final-pose on the M folds: refuses
// (exit 5) K, writes fit N, ..." (each decision and how often, sorted).
std::string FoldDecisionsLine(const std::vector<SplitCalibration>& folds);

// The flags the library reads as given.
struct GeneraliseOptions {
  bool leave_one_session_out = true;
  // Non-empty: instead of every pair of path types, train on the runs whose trajectory label
  // matches (fit/trajectory_split.h: a list of labels or a regular expression) and test on
  // the others, then the other way round.
  std::string train_trajectories;
  // The repetitions that train the "every path type" split ("auto": the first half of those
  // present, fit/run_split.h).
  std::string train_reps = "auto";
  // Score the method published with the OptiOdom recordings as one more candidate (needs
  // ground-truth tracks). Off by default: its checkpoint cost costs more than the fit (omni4's
  // leave-one-session-out 32 -> 60 s on one core).
  bool optiodom = false;
};

struct GeneraliseRequest {
  // Asked: the flags, in the library's terms.
  GeneraliseOptions options;
  std::string dataset;   // --logs, for messages
  EffectModel effects;   // non-empty: the track fit alone and with these effects compete
  ParameterTying tying;  // non-empty: every fit made once more on the reduced model
  SessionKey sessions = SessionKey::kLabel;
  int threads = 0;
  std::vector<RunLog> logs;  // every run of the data set
  // Decided by MakeGeneraliseRequest.
  std::vector<AlignedRun> runs;  // AlignRuns(logs)
  std::vector<std::vector<Segment>> optiodom_checkpoints;  // one per run, with optiodom
  std::vector<TrackRun> tracks;  // with effects
  bool dense_tracks = false;     // the track fit competes (fit/residual_choice.h)
  std::vector<GeneralisationSplit> table_splits, folds;  // folds: empty without
};

// The asked request with its decisions, the runs read with `robot`'s channels. Throws UsageError
// (exit 2, one line) when optiodom meets a run with no pose between its ends, or when
// train_trajectories or train_reps leaves a side empty.
GeneraliseRequest MakeGeneraliseRequest(GeneraliseRequest asked, const Robot& robot);

struct GeneraliseOutcome {
  std::vector<SplitCalibration> table;  // one per table split
  // Each written fit of each table split against the nominal on its held-out runs, titled
  // "<train> -> <test>: <candidate>".
  std::vector<std::pair<std::string, EverydayDrivingComparison>> everyday_driving;
  std::vector<SplitCalibration> folds;
  std::vector<FoldSummary> fold_summary;
};

// `on_table_split`, when given, sees each table split as soon as it is done (the command prints
// its rows while the next one is fitted).
GeneraliseOutcome Generalise(
    const GeneraliseRequest& request, const RobotModelInterface& model,
    const std::function<void(const SplitCalibration&)>& on_table_split = {});

}  // namespace fitcal
