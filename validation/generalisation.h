#pragma once
// How well a calibration transfers to runs it was not fitted on, for any robot model
// (models/model_interface.h). A split names training and held-out runs; on each split every
// candidate the result gate would see - the nominal robot, the model's closed forms computed from
// the training runs (UMBmark for diff_drive), the bounded fit (fit/model_fit.h) and, when it held
// directions the training runs do not determine, the fit without those holds - and, when the
// ground truth is a track, the method published with the OptiOdom recordings (EvaluateSplit) is
// scored on the held-out runs: CF (Palacin Eq. 14), mean final position error and mean |heading
// error|.
//
// The held-out runs only score here; nothing is selected on them (a gate choosing on the runs it
// is then scored on would report the best of several candidates as if it had been chosen blind).
//
// Splits:
//   - path types: the trajectory label up to its first '_' or '/' (`circular` of
//     `circular_231220200121` or `circular/231220200121`, as `fitcal import optiodom` writes them);
//     train on one, test on each other one;
//   - a predicate (e.g. a --train-trajectories selector): its runs against the rest, both ways;
//   - repetitions: training repetitions of every path type against the other repetitions;
//   - leave-one-session-out: every session held out once, the others train.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fit/effect_fit.h"
#include "fit/final_pose_errors.h"
#include "fit/model_fit.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

// The label up to its first '_' or '/' (the whole label when it has neither).
std::string PathTypeOf(const std::string& trajectory_label);

struct GeneralisationSplit {
  std::string train_name;
  std::string test_name;
  std::vector<std::size_t> train;  // indices into the runs
  std::vector<std::size_t> test;
};

// Every ordered pair of distinct path types present, in sorted order.
std::vector<GeneralisationSplit> PathTypeSplits(const std::vector<AlignedRun>& runs);

// The runs for which `trains` holds against the rest, then the other way round. Empty when
// either side has no run.
std::vector<GeneralisationSplit> PredicateSplits(
    const std::vector<AlignedRun>& runs, const std::function<bool(const AlignedRun&)>& trains,
    const std::string& train_name, const std::string& test_name);

// The runs of the repetitions `train_reps` names (fit/run_split.h: "auto", the first half present)
// of every path type against the other repetitions, one direction only: the other would train on
// what was meant to be held out. nullopt when "auto" leaves a side empty (one repetition in the
// data set); a UsageError (exit 2) when repetitions the user named do - none of them in the data
// set, or every repetition - since the split asked for would otherwise be left out unsaid.
std::optional<GeneralisationSplit> RepetitionSplit(const std::vector<AlignedRun>& runs,
                                                   const std::string& train_reps);

// What a session is in a data set. OptiOdom's omni3, omni4 and diff_drive imports give every
// recording session its own trajectory label; its tricycle import labels runs by path type and
// direction (`circular_cw`) and numbers the sessions of each path type as repetitions.
enum class SessionKey {
  kLabel,                  // the whole trajectory label
  kPathTypeAndRepetition,  // path type + repetition number
};

// One split per session (sorted), holding it out; the others train. Empty with fewer than two
// sessions.
std::vector<GeneralisationSplit> LeaveOneSessionOutSplits(const std::vector<AlignedRun>& runs,
                                                          SessionKey key);

struct CandidateScore {
  std::string name;  // "nominal", "umbmark", "fit", "fit without holds", "fit (tied)", ...
  bool usable = true;
  std::vector<double> parameters;
  FinalPoseErrors train;
  FinalPoseErrors test;
  bool is_fit = false;  // the two fields below apply
  int held_directions = 0;
  int at_bound = 0;
};

struct SplitScores {
  GeneralisationSplit split;
  std::vector<CandidateScore> candidates;  // nominal first
};

// Further candidates of EvaluateSplit, for data whose ground truth is a track.
struct TrackCandidates {
  // The method published with the OptiOdom recordings, "optiodom": Sousa et al.'s cost (squared
  // position error from the start at every checkpoint) minimised over every parameter from the
  // nominal, nothing held, within the model's bounds - the minimum their resilient
  // back-propagation searches for, found here by the fit's own Ceres solve. One list per run of
  // `runs` (fit/segment_cost.h MakeCheckpointsFromStart).
  const std::vector<std::vector<Segment>>* optiodom_checkpoints = nullptr;
  // The model's parameters fitted on the training tracks (fit/effect_fit.h) alone, "track
  // fit", and with these library effects, "track fit + <names>": what closing the loop gains on
  // the held-out runs, like for like. One TrackRun per run of `runs`; used when `effects` is not
  // empty.
  const std::vector<TrackRun>* tracks = nullptr;
  EffectModel effects;
  // The bounded fit on the training runs' track residuals (fit/track_residual.h, no clock
  // offsets), "fit (track)", beside the final-pose "fit": what `fit --residuals auto` writes on
  // dense ground-truth tracks. One ground truth per run of `runs`.
  const std::vector<const GroundTruthTrack*>* ground_truth = nullptr;
};

// The names of the fits' candidates, and of the tied fits' (EvaluateSplit with a tying).
inline constexpr const char* kFitName = "fit";
inline constexpr const char* kTrackFitName = "fit (track)";
inline constexpr const char* kTiedFitName = "fit (tied)";
inline constexpr const char* kTiedTrackFitName = "fit (track, tied)";

// A calibration `fit` writes (the final-pose or the track fit, or a tied twin): the candidates
// whose everyday driving `generalise` prints. With final_pose_only, the final-pose ones only: the
// candidates whose held directions and parameters at a bound its table shows.
bool IsWrittenFit(const CandidateScore& candidate, bool final_pose_only = false);

// Fits on split.train (options.ceres.num_threads also drives the evaluation) and scores every
// candidate on split.test. With a non-empty `tying` (fit/parameter_tying.h: a reduced model such
// as OptiOdom's omni3, `--tie`/`--hold`), each fit of the full model is made once more on the
// tied model and scored right after it: "fit (tied)" (and "fit (tied) without holds" when it
// held directions) after "fit", "fit (track, tied)" after "fit (track)". options.tying is
// ignored: the full fits stay full. Throws std::invalid_argument when either side is empty.
// `fit`, when given, is the final-pose fit of split.train already made (by calibrate/
// generalise.h, the fit `fit` makes and gates), scored as "fit" instead of fitting again.
SplitScores EvaluateSplit(const RobotModelInterface& model, const std::vector<AlignedRun>& runs,
                          const GeneralisationSplit& split, const ModelFitOptions& options,
                          const TrackCandidates& track_candidates = {},
                          const ParameterTying& tying = {}, const ModelFitResult* fit = nullptr);

// One candidate over the folds of leave-one-session-out (candidates are matched by name; a closed
// form may exist in some folds only).
struct FoldSummary {
  std::string name;
  int folds = 0;                 // folds in which the candidate existed
  int unusable_folds = 0;        // of those, folds where it did not converge (still scored)
  double mean_session_cf = 0.0;  // mean over folds of the held-out session's CF
  double run_cf = 0.0;           // mean over every held-out run (Eq. 14 over the runs)
  double run_position_m = 0.0;   // mean final position error over every held-out run
  double run_heading_rad = 0.0;  // mean |final heading error| over every held-out run
  int folds_with_held_directions = 0;
  int folds_at_bound = 0;
};

std::vector<FoldSummary> SummariseFolds(const std::vector<SplitScores>& folds);

}  // namespace fitcal
