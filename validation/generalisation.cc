#include "validation/generalisation.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include "fit/run_split.h"
#include "io/command_failure.h"

namespace fitcal {

namespace {

CandidateScore Score(const RobotModelInterface& model, std::string name,
                     std::vector<double> parameters, bool usable,
                     const std::vector<AlignedRun>& train, const std::vector<AlignedRun>& test,
                     int threads) {
  CandidateScore s;
  s.name = std::move(name);
  s.usable = usable;
  s.parameters = std::move(parameters);
  s.train = EvaluateFinalPoseErrors(model, s.parameters, train, threads);
  s.test = EvaluateFinalPoseErrors(model, s.parameters, test, threads);
  return s;
}

// Sousa et al.'s OptiOdom calibration of the training runs (see EvaluateSplit in the header).
CandidateScore OptiOdomCandidate(const RobotModelInterface& model,
                                 const std::vector<AlignedRun>& train,
                                 const std::vector<AlignedRun>& test,
                                 const std::vector<std::vector<Segment>>& train_checkpoints,
                                 const ModelFitOptions& options) {
  ModelFitOptions o = options;
  o.segments = &train_checkpoints;
  o.hold_undetermined = false;  // their method moves every parameter
  o.ceres.objective = FinalPoseObjective::kSumOfSquares;
  o.ceres.loss = CeresRobustLoss::kNone;
  o.ceres.compute_covariance = false;
  o.ceres.weights.position_sigma_m = 1.0;
  // Their cost has no heading term: a heading sigma of 1e6 rad weighs it 1e-12 against 1 m.
  o.ceres.weights.heading_sigma_rad = 1e6;
  const ModelFitResult fit = FitModel(train, model, o);
  CandidateScore s =
      Score(model, "optiodom", fit.parameters, fit.usable, train, test, options.ceres.num_threads);
  s.is_fit = true;
  for (bool b : fit.at_bound) s.at_bound += b;
  return s;
}

// The model's parameters and `effects` fitted on the training tracks, scored on the held-out ones.
CandidateScore TrackFitCandidate(const RobotModelInterface& model, const std::string& name,
                                 const std::vector<TrackRun>& train,
                                 const std::vector<TrackRun>& test, const EffectModel& effects,
                                 int threads) {
  EffectFitOptions o;
  o.num_threads = threads;
  o.compute_covariance = false;
  const EffectFitResult fit = FitEffectModel(train, model, model.robot().nominal, effects, o);
  CandidateScore s;
  s.name = name;
  s.usable = fit.usable;
  s.parameters = fit.parameters;
  s.is_fit = true;
  s.at_bound = fit.any_at_bound ? 1 : 0;
  s.train = FinalPoseErrorsOf(ScoreModel(model, fit.parameters, fit.effects, train, {}, threads));
  s.test = FinalPoseErrorsOf(ScoreModel(model, fit.parameters, fit.effects, test, {}, threads));
  return s;
}

// A fit of the split's training runs, scored, with what it held and where it hit a bound.
CandidateScore FitCandidate(const RobotModelInterface& model, const std::string& name,
                            const ModelFitResult& fit, const std::vector<AlignedRun>& train,
                            const std::vector<AlignedRun>& test, int threads) {
  CandidateScore s = Score(model, name, fit.parameters, fit.usable, train, test, threads);
  s.is_fit = true;
  s.held_directions = static_cast<int>(fit.held_directions.size());
  for (bool b : fit.at_bound) s.at_bound += b;
  return s;
}

// The bounded final-pose fit `name` and, when it held directions the training runs do not
// determine, the gate's "<name> without holds" candidate: what fitting those directions too
// would have given, so the table shows what holding them gained or cost on the held-out runs.
// `made`, when given, is that fit already made.
void AddFinalPoseFits(const RobotModelInterface& model, const std::string& name,
                      const ModelFitOptions& options, const std::vector<AlignedRun>& train,
                      const std::vector<AlignedRun>& test, std::vector<CandidateScore>* out,
                      const ModelFitResult* made = nullptr) {
  const int threads = options.ceres.num_threads;
  const ModelFitResult fit = made != nullptr ? *made : FitModel(train, model, options);
  out->push_back(FitCandidate(model, name, fit, train, test, threads));
  if (fit.held_directions.empty()) return;
  CandidateScore free = Score(model, name + " without holds", fit.unconstrained_parameters,
                              fit.unconstrained_usable, train, test, threads);
  free.is_fit = true;
  out->push_back(std::move(free));
}

// The bounded fit `name` on the training runs' track residuals (fit/track_residual.h, no clock
// offsets): what `fit --residuals auto` writes on dense ground-truth tracks.
void AddTrackFit(const RobotModelInterface& model, const std::string& name,
                 const ModelFitOptions& options, const TrackFitData& data,
                 const std::vector<AlignedRun>& train, const std::vector<AlignedRun>& test,
                 std::vector<CandidateScore>* out) {
  ModelFitOptions track_options = options;
  track_options.residuals = ResidualKind::kTrack;
  track_options.track = &data;
  const ModelFitResult fit = FitModel(train, model, track_options);
  out->push_back(FitCandidate(model, name, fit, train, test, options.ceres.num_threads));
}

template <typename T>
std::vector<T> PickEach(const std::vector<T>& all, const std::vector<std::size_t>& indices) {
  std::vector<T> out;
  out.reserve(indices.size());
  for (std::size_t i : indices) out.push_back(all.at(i));
  return out;
}

std::string SessionOf(const AlignedRun& run, SessionKey key) {
  if (key == SessionKey::kLabel) return run.trajectory;
  return PathTypeOf(run.trajectory) + " " + std::to_string(run.repetition);
}

}  // namespace

std::string PathTypeOf(const std::string& trajectory_label) {
  return trajectory_label.substr(0, trajectory_label.find_first_of("_/"));
}

std::vector<GeneralisationSplit> PathTypeSplits(const std::vector<AlignedRun>& runs) {
  std::set<std::string> types;
  for (const AlignedRun& run : runs) types.insert(PathTypeOf(run.trajectory));
  std::vector<GeneralisationSplit> out;
  for (const std::string& train_type : types) {
    for (const std::string& test_type : types) {
      if (train_type == test_type) continue;
      GeneralisationSplit s{train_type, test_type, {}, {}};
      for (std::size_t i = 0; i < runs.size(); ++i) {
        const std::string type = PathTypeOf(runs[i].trajectory);
        if (type == train_type) s.train.push_back(i);
        if (type == test_type) s.test.push_back(i);
      }
      out.push_back(std::move(s));
    }
  }
  return out;
}

std::vector<GeneralisationSplit> PredicateSplits(
    const std::vector<AlignedRun>& runs, const std::function<bool(const AlignedRun&)>& trains,
    const std::string& train_name, const std::string& test_name) {
  GeneralisationSplit a{train_name, test_name, {}, {}};
  for (std::size_t i = 0; i < runs.size(); ++i) (trains(runs[i]) ? a.train : a.test).push_back(i);
  if (a.train.empty() || a.test.empty()) return {};
  GeneralisationSplit b{test_name, train_name, a.test, a.train};
  return {a, b};
}

std::optional<GeneralisationSplit> RepetitionSplit(const std::vector<AlignedRun>& runs,
                                                   const std::string& train_reps) {
  std::set<int> present;
  for (const AlignedRun& run : runs) present.insert(run.repetition);
  const std::vector<int> reps = ResolveRepetitionList(train_reps, present);
  const std::set<int> rep_set(reps.begin(), reps.end());
  const std::string named = FormatRepetitionList(reps);
  std::vector<GeneralisationSplit> both = PredicateSplits(
      runs, [&](const AlignedRun& run) { return rep_set.count(run.repetition) > 0; },
      "every path type, reps " + named, "the other reps");
  if (!both.empty()) return std::move(both.front());
  if (train_reps == "auto") return std::nullopt;
  const bool none = std::none_of(runs.begin(), runs.end(), [&](const AlignedRun& run) {
    return rep_set.count(run.repetition) > 0;
  });
  throw UsageError("--train-reps " + train_reps + ": " +
                   (none ? "no run of the data set is of repetition " + named
                         : "every run of the data set is of repetition " + named +
                               ", none left to test on") +
                   " (repetitions present: " +
                   FormatRepetitionList(std::vector<int>(present.begin(), present.end())) + ")");
}

std::vector<GeneralisationSplit> LeaveOneSessionOutSplits(const std::vector<AlignedRun>& runs,
                                                          SessionKey key) {
  std::set<std::string> sessions;
  for (const AlignedRun& run : runs) sessions.insert(SessionOf(run, key));
  if (sessions.size() < 2) return {};
  std::vector<GeneralisationSplit> out;
  for (const std::string& held_out : sessions) {
    GeneralisationSplit s{"all but " + held_out, held_out, {}, {}};
    for (std::size_t i = 0; i < runs.size(); ++i)
      (SessionOf(runs[i], key) == held_out ? s.test : s.train).push_back(i);
    out.push_back(std::move(s));
  }
  return out;
}

SplitScores EvaluateSplit(const RobotModelInterface& model, const std::vector<AlignedRun>& runs,
                          const GeneralisationSplit& split, const ModelFitOptions& options,
                          const TrackCandidates& track_candidates, const ParameterTying& tying,
                          const ModelFitResult* fit) {
  if (split.train.empty() || split.test.empty()) {
    throw std::invalid_argument("generalisation split '" + split.train_name + "' -> '" +
                                split.test_name + "' has no training or no held-out run");
  }
  const std::vector<AlignedRun> train = PickEach(runs, split.train);
  const std::vector<AlignedRun> test = PickEach(runs, split.test);
  const int threads = options.ceres.num_threads;
  SplitScores out;
  out.split = split;
  out.candidates.push_back(
      Score(model, "nominal", model.robot().nominal, true, train, test, threads));
  for (const ClosedFormCalibration& c : model.ClosedForms(train)) {
    out.candidates.push_back(Score(model, c.method, c.parameters, true, train, test, threads));
  }
  ModelFitOptions full = options;
  full.tying = nullptr;
  AddFinalPoseFits(model, kFitName, full, train, test, &out.candidates, fit);
  ModelFitOptions tied = full;
  tied.tying = &tying;
  if (!tying.empty()) AddFinalPoseFits(model, kTiedFitName, tied, train, test, &out.candidates);
  if (const auto* ground_truth = track_candidates.ground_truth) {
    if (ground_truth->size() != runs.size()) {
      throw std::invalid_argument("EvaluateSplit: not one ground truth per run");
    }
    const TrackFitData data =
        MakeTrackFitData(train, PickEach(*ground_truth, split.train), ClockGrouping::kNone);
    AddTrackFit(model, kTrackFitName, full, data, train, test, &out.candidates);
    if (!tying.empty())
      AddTrackFit(model, kTiedTrackFitName, tied, data, train, test, &out.candidates);
  }
  if (const auto* checkpoints = track_candidates.optiodom_checkpoints) {
    if (checkpoints->size() != runs.size()) {
      throw std::invalid_argument("EvaluateSplit: not one checkpoint list per run");
    }
    const std::vector<std::vector<Segment>> train_checkpoints = PickEach(*checkpoints, split.train);
    out.candidates.push_back(OptiOdomCandidate(model, train, test, train_checkpoints, full));
  }
  if (track_candidates.tracks != nullptr && !track_candidates.effects.empty()) {
    const std::vector<TrackRun>& tracks = *track_candidates.tracks;
    if (tracks.size() != runs.size()) {
      throw std::invalid_argument("EvaluateSplit: not one track per run");
    }
    const std::vector<TrackRun> train_tracks = PickEach(tracks, split.train);
    const std::vector<TrackRun> test_tracks = PickEach(tracks, split.test);
    std::string with = "track fit +";
    for (const effects::EffectValue& e : track_candidates.effects) {
      with += std::string(" ") + effects::Info(e.id).name;
    }
    out.candidates.push_back(
        TrackFitCandidate(model, "track fit", train_tracks, test_tracks, {}, threads));
    out.candidates.push_back(TrackFitCandidate(model, with, train_tracks, test_tracks,
                                               track_candidates.effects, threads));
  }
  return out;
}

std::vector<FoldSummary> SummariseFolds(const std::vector<SplitScores>& folds) {
  std::vector<FoldSummary> out;
  std::map<std::string, std::size_t> index;
  std::map<std::string, int> runs;  // held-out runs per candidate
  for (const SplitScores& fold : folds) {
    const int n = static_cast<int>(fold.split.test.size());
    for (const CandidateScore& c : fold.candidates) {
      auto it = index.find(c.name);
      if (it == index.end()) {
        it = index.emplace(c.name, out.size()).first;
        out.push_back(FoldSummary{});
        out.back().name = c.name;
      }
      FoldSummary& s = out[it->second];
      ++s.folds;
      s.unusable_folds += !c.usable;
      s.mean_session_cf += c.test.cf;
      s.run_cf += c.test.cf * n;
      s.run_position_m += c.test.mean_position_error_m * n;
      s.run_heading_rad += c.test.mean_abs_heading_error_rad * n;
      s.folds_with_held_directions += c.held_directions > 0;
      s.folds_at_bound += c.at_bound > 0;
      runs[c.name] += n;
    }
  }
  for (FoldSummary& s : out) {
    const double n = runs[s.name];
    s.mean_session_cf /= s.folds;
    s.run_cf /= n;
    s.run_position_m /= n;
    s.run_heading_rad /= n;
  }
  return out;
}

bool IsWrittenFit(const CandidateScore& candidate, bool final_pose_only) {
  const std::string& name = candidate.name;
  if (name == kFitName || name == kTiedFitName) return true;
  return !final_pose_only && (name == kTrackFitName || name == kTiedTrackFitName);
}

}  // namespace fitcal
