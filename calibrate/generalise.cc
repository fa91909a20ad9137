#include "calibrate/generalise.h"

#include <map>
#include <set>

#include "fit/residual_choice.h"
#include "fit/trajectory_split.h"
#include "io/command_failure.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

// The method `fit` uses by default, whose fit the table calls "fit".
constexpr const char* kMethod = "ceres";

// A gate candidate's name as the table writes it ("ceres ..." -> "fit ...").
std::string TableName(const std::string& name) {
  const std::string method = kMethod;
  if (name.compare(0, method.size(), method) != 0) return name;
  return "fit" + name.substr(method.size());
}

// The split as a calibration request: its runs (in the data set's order), its training runs by
// id, fit's defaults (the effects the robot declares refitted, as fit refits them), nothing
// written.
CalibrationRequest SplitRequest(const Robot& robot, const std::vector<RunLog>& logs,
                                const GeneralisationSplit& split, int threads) {
  CalibrationRequest r;
  r.effects_to_fit = robot.effects;
  r.dataset = "split " + split.train_name + " -> " + split.test_name;
  r.method = FindFitMethod(kMethod);
  r.settings.threads = threads;
  r.threads = threads;
  std::set<std::size_t> in_split(split.train.begin(), split.train.end());
  in_split.insert(split.test.begin(), split.test.end());
  for (std::size_t i : in_split) r.runs.push_back(logs.at(i));
  for (std::size_t i : split.train) r.training_ids.push_back(logs.at(i).id);
  r.check_channel_order = false;
  r.will_write = false;
  return r;
}

// The split calibrated as `fit` calibrates it (Ceres, final poses; no channel-order check: the
// data set's wiring does not change between splits), then every candidate scored on it.
SplitCalibration CalibrateSplit(const GeneraliseRequest& request, const RobotModelInterface& model,
                                const TrackCandidates& candidates,
                                const GeneralisationSplit& split) {
  ModelFitOptions options;
  options.ceres.num_threads = request.threads;
  SplitCalibration out;
  out.outcome = Calibrate(SplitRequest(model.robot(), request.logs, split, request.threads), model);
  // A refusal before the fit (the data's checks, too few residuals) leaves the table to fit the
  // split itself; its decision line says why `fit` would not.
  const ModelFitResult* fit = out.outcome.candidates.empty() ? nullptr : &out.outcome.fit.fit;
  out.scores = EvaluateSplit(model, request.runs, split, options, candidates, request.tying, fit);
  return out;
}

// The splits of the table: every ordered pair of path types (or the --train-trajectories
// selection against the rest, both ways), then the training repetitions of every path type
// against the others.
std::vector<GeneralisationSplit> TableSplits(const GeneraliseOptions& options,
                                             const std::vector<AlignedRun>& runs) {
  std::vector<GeneralisationSplit> splits;
  if (!options.train_trajectories.empty()) {
    std::vector<std::string> labels;
    for (const AlignedRun& run : runs) labels.push_back(run.trajectory);
    const TrajectorySelector selector(options.train_trajectories, labels);
    splits = PredicateSplits(
        runs, [&](const AlignedRun& run) { return selector.Matches(run.trajectory); },
        "'" + options.train_trajectories + "'", "others");
    if (splits.empty()) {
      throw UsageError("--train-trajectories '" + options.train_trajectories +
                       "' must select some runs and leave some out");
    }
  } else {
    splits = PathTypeSplits(runs);
  }
  if (std::optional<GeneralisationSplit> s = RepetitionSplit(runs, options.train_reps)) {
    splits.push_back(std::move(*s));
  }
  return splits;
}

// The everyday-driving comparison `fit` prints, nominal against each fit of the split ("fit",
// "fit (track)": the calibrations `fit` writes, and their tied twins), on its held-out runs.
void AddEverydayDriving(const GeneraliseRequest& request, const RobotModelInterface& model,
                        const SplitScores& scores, GeneraliseOutcome* out) {
  std::vector<AlignedRun> held_out;
  for (std::size_t i : scores.split.test) held_out.push_back(request.runs[i]);
  const CandidateScore& nominal = scores.candidates.front();
  for (const CandidateScore& c : scores.candidates) {
    if (!IsWrittenFit(c)) continue;
    out->everyday_driving.emplace_back(
        scores.split.train_name + " -> " + scores.split.test_name + ": " + c.name,
        CompareEverydayDriving(model, {nominal.name, nominal.parameters}, {c.name, c.parameters},
                               held_out, TracksOf(held_out), request.threads));
  }
}

}  // namespace

std::string DecisionLine(const CalibrationOutcome& outcome) {
  if (outcome.refusal.exit_code != 0) {
    std::string line = "refuses (exit " + std::to_string(outcome.refusal.exit_code) + "):";
    for (std::size_t k = 0; k < outcome.refusal.reasons.size(); ++k) {
      line += (k == 0 ? " " : "; ") + outcome.refusal.reasons[k];
    }
    return line;
  }
  const GateDecision& gate = outcome.gate;
  return "writes " + TableName(outcome.selected().name) + " (" + gate.judged_on + ": " +
         StrFormat("CF %.4f -> %.4f", gate.cf.front(), gate.cf.at(gate.selected)) + ")";
}

std::string FoldDecisionsLine(const std::vector<SplitCalibration>& folds) {
  std::map<std::string, int> count;  // per decision: "refuses (exit 5)", "writes fit", ...
  for (const SplitCalibration& fold : folds) {
    const CalibrationOutcome& o = fold.outcome;
    ++count[o.refusal.exit_code != 0 ? "refuses (exit " + std::to_string(o.refusal.exit_code) + ")"
                                     : "writes " + TableName(o.selected().name)];
  }
  std::string line =
      "fit --residuals final-pose on the " + std::to_string(folds.size()) + " folds:";
  for (const auto& [decision, n] : count) line += " " + decision + " " + std::to_string(n) + ",";
  line.pop_back();
  return line;
}

GeneraliseRequest MakeGeneraliseRequest(GeneraliseRequest r, const Robot& robot) {
  r.runs = AlignRuns(r.logs);
  for (std::size_t i = 0; i < r.runs.size() && r.options.optiodom; ++i) {
    // OptiOdom's checkpoints every 0.5 m of path, as Sousa et al.: their cost needs the track.
    if (r.logs[i].ground_truth.t_s.size() < 3) {
      throw UsageError("generalise --optiodom: " + r.dataset +
                       ": OptiOdom's method needs a ground-truth track (poses between each run's "
                       "start and end), and some run has only its ends");
    }
    r.optiodom_checkpoints.push_back(
        MakeCheckpointsFromStart(r.runs[i], r.logs[i].ground_truth, /*spacing_m=*/0.5));
  }
  if (!r.effects.empty()) r.tracks = PrepareTrackRuns(r.logs, WheelChannelMask(robot));
  r.dense_tracks = MeasureTrackDensity(r.runs, TracksOf(r.runs)).dense;
  r.table_splits = TableSplits(r.options, r.runs);
  if (r.options.leave_one_session_out) r.folds = LeaveOneSessionOutSplits(r.runs, r.sessions);
  return r;
}

GeneraliseOutcome Generalise(const GeneraliseRequest& request, const RobotModelInterface& model,
                             const std::function<void(const SplitCalibration&)>& on_table_split) {
  const std::vector<const GroundTruthTrack*> ground_truth = TracksOf(request.runs);
  TrackCandidates candidates;
  if (request.options.optiodom) candidates.optiodom_checkpoints = &request.optiodom_checkpoints;
  if (!request.effects.empty()) {
    candidates.tracks = &request.tracks;
    candidates.effects = request.effects;
  }
  if (request.dense_tracks) candidates.ground_truth = &ground_truth;
  GeneraliseOutcome out;
  for (const GeneralisationSplit& split : request.table_splits) {
    out.table.push_back(CalibrateSplit(request, model, candidates, split));
    if (on_table_split) on_table_split(out.table.back());
  }
  for (const SplitCalibration& s : out.table) {
    AddEverydayDriving(request, model, s.scores, &out);
  }
  std::vector<SplitScores> fold_scores;
  for (const GeneralisationSplit& split : request.folds) {
    out.folds.push_back(CalibrateSplit(request, model, candidates, split));
    fold_scores.push_back(out.folds.back().scores);
  }
  if (!out.folds.empty()) out.fold_summary = SummariseFolds(fold_scores);
  return out;
}

}  // namespace fitcal
