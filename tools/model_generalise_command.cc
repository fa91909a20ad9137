#include "tools/model_generalise_command.h"

#include <cstdio>
#include <iostream>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

#include "fit/effect_fit.h"
#include "fit/residual_choice.h"
#include "fit/run_split.h"
#include "fit/segment_cost.h"
#include "fit/trajectory_split.h"
#include "tools/effect_list.h"
#include "validation/generalisation.h"

namespace fitcal::tools {

namespace {

// "auto": the first half of the repetitions present (rounded up), as `diagnose` splits.
std::vector<int> TrainingRepetitions(const std::string& text, const std::vector<AlignedRun>& runs) {
  if (!text.empty() && text != "auto") return ParseRepetitionList(text);
  std::set<int> present;
  for (const AlignedRun& run : runs) present.insert(run.repetition);
  const std::vector<int> all(present.begin(), present.end());
  return std::vector<int>(all.begin(), all.begin() + static_cast<long>((all.size() + 1) / 2));
}

void PrintSplitTableHeader() {
  std::printf(
      "| trained on -> tested on | candidate | train runs | held-out runs | train CF | held-out "
      "CF | held-out pos. [m] | held-out head. [deg] | held directions | params at bound |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n");
}

void PrintSplitRows(const SplitScores& s) {
  for (const CandidateScore& c : s.candidates) {
    char held[16] = "-", bound[16] = "-";
    if (c.is_fit && c.name == "fit") {
      std::snprintf(held, sizeof held, "%d", c.held_directions);
      std::snprintf(bound, sizeof bound, "%d", c.at_bound);
    }
    std::printf("| %s -> %s | %s%s | %zu | %zu | %.4f | %.4f | %.3f | %.2f | %s | %s |\n",
                s.split.train_name.c_str(), s.split.test_name.c_str(), c.name.c_str(),
                c.usable ? "" : " (not converged)", s.split.train.size(), s.split.test.size(),
                c.train.cf, c.test.cf, c.test.mean_position_error_m,
                RadToDeg(c.test.mean_abs_heading_error_rad), held, bound);
  }
}

// The summary over the folds, then the held-out CF of every candidate per session.
void PrintLeaveOneSessionOut(const std::vector<SplitScores>& folds) {
  const std::vector<FoldSummary> summary = SummariseFolds(folds);
  std::printf(
      "\nleave-one-session-out (%zu sessions, each held out once)\n\n"
      "| candidate | folds | mean of the sessions' CF | CF over the held-out runs | pos. [m] | "
      "head. [deg] | folds with held directions | folds with a parameter at a bound |\n"
      "|---|---|---|---|---|---|---|---|\n",
      folds.size());
  for (const FoldSummary& s : summary) {
    const std::string unusable =
        s.unusable_folds > 0 ? " (" + std::to_string(s.unusable_folds) + " not converged)" : "";
    std::printf("| %s | %d%s | %.4f | %.4f | %.3f | %.2f | %d | %d |\n", s.name.c_str(), s.folds,
                unusable.c_str(), s.mean_session_cf, s.run_cf, s.run_position_m,
                RadToDeg(s.run_heading_rad), s.folds_with_held_directions, s.folds_at_bound);
  }
  std::printf("\n| held-out session | runs |");
  for (const FoldSummary& s : summary) std::printf(" %s |", s.name.c_str());
  std::printf("\n|---|---|");
  for (std::size_t k = 0; k < summary.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (const SplitScores& fold : folds) {
    std::printf("| %s | %zu |", fold.split.test_name.c_str(), fold.split.test.size());
    for (const FoldSummary& s : summary) {
      const CandidateScore* found = nullptr;
      for (const CandidateScore& c : fold.candidates)
        if (c.name == s.name) found = &c;
      if (found == nullptr) {
        std::printf(" - |");
      } else {
        std::printf(" %.4f |", found->test.cf);
      }
    }
    std::printf("\n");
  }
}

// Refuses the omni3-only flags in one line rather than ignoring them.
bool RefuseOmni3OnlyOptions(const GeneraliseCommandOptions& o, const std::string& model) {
  std::string flag;
  if (!o.clock_map) flag = "--no-clock-map";
  const GeneraliseCommandOptions defaults;
  if (o.segment_length_m != defaults.segment_length_m) flag = "--segment-length-m";
  if (flag.empty()) return false;
  std::cerr << "fitcal: generalise " << flag << " belongs to the omni3 table (segment cost); "
            << "not available for model " << model << "\n";
  return true;
}

// OptiOdom's checkpoints (every 0.5 m of path, as Sousa et al.) for every run, or nothing when
// some run's ground truth holds no pose between its start and end (their cost needs the track).
std::optional<std::vector<std::vector<Segment>>> OptiOdomCheckpoints(
    const std::vector<AlignedRun>& runs, const std::vector<RunLog>& logs) {
  constexpr double kSpacingM = 0.5;
  std::vector<std::vector<Segment>> out;
  for (std::size_t i = 0; i < runs.size(); ++i) {  // runs = AlignRuns(logs), in the same order
    const GroundTruthTrack& track = logs[i].ground_truth;
    if (track.t_s.size() < 3) return std::nullopt;
    out.push_back(MakeCheckpointsFromStart(runs[i], track, kSpacingM));
  }
  return out;
}

}  // namespace

int RunModelGeneraliseCommand(const GeneraliseCommandOptions& options,
                              const io::DatasetIndex& index, const RobotModelPtr& model) {
  const Robot& robot = model->robot();
  if (RefuseOmni3OnlyOptions(options, robot.model)) return 2;
  SessionKey session_key = SessionKey::kLabel;
  if (options.sessions == "repetition") {
    session_key = SessionKey::kPathTypeAndRepetition;
  } else if (options.sessions != "label") {
    std::cerr << "fitcal: unknown --sessions '" << options.sessions
              << "' (available: label, repetition)\n";
    return 2;
  }
  const io::Dataset dataset = LoadRuns(options, index, &robot);
  const std::vector<AlignedRun> runs = AlignRuns(dataset.runs);
  TrackCandidates track_candidates;
  std::optional<std::vector<std::vector<Segment>>> checkpoints;
  if (options.optiodom) {
    checkpoints = OptiOdomCheckpoints(runs, dataset.runs);
    if (!checkpoints) {
      std::cerr << "fitcal: generalise --optiodom: " << options.logs
                << ": OptiOdom's method needs a ground-truth track (poses between each run's "
                   "start and end), and some run has only its ends\n";
      return 2;
    }
    track_candidates.optiodom_checkpoints = &*checkpoints;
  }
  const std::optional<EffectModel> effect_list =
      ReadEffectList(options.effects, robot, "generalise");
  if (!effect_list) return 2;
  std::vector<TrackRun> tracks;
  if (!effect_list->empty()) {
    tracks = PrepareTrackRuns(dataset.runs, WheelChannelMask(robot));
    track_candidates.tracks = &tracks;
    track_candidates.effects = *effect_list;
  }
  // On dense ground-truth tracks (fit/residual_choice.h, as fit --residuals auto decides) the
  // track fit competes too.
  std::vector<const GroundTruthTrack*> ground_truth;
  for (const RunLog& log : dataset.runs) ground_truth.push_back(&log.ground_truth);
  if (MeasureTrackDensity(runs, ground_truth).dense) track_candidates.ground_truth = &ground_truth;
  ModelFitOptions fit_options;
  fit_options.ceres.num_threads = options.threads;

  std::vector<GeneralisationSplit> splits;
  if (!options.train_trajectories.empty()) {
    std::vector<std::string> labels;
    for (const AlignedRun& run : runs) labels.push_back(run.trajectory);
    const TrajectorySelector selector(options.train_trajectories, labels);
    splits = PredicateSplits(
        runs, [&](const AlignedRun& run) { return selector.Matches(run.trajectory); },
        "'" + options.train_trajectories + "'", "others");
    if (splits.empty()) {
      std::cerr << "fitcal: --train-trajectories '" << options.train_trajectories
                << "' must select some runs and leave some out\n";
      return 2;
    }
  } else {
    splits = PathTypeSplits(runs);
  }
  const std::vector<int> reps = TrainingRepetitions(options.train_reps, runs);
  const std::set<int> rep_set(reps.begin(), reps.end());
  for (GeneralisationSplit& s : PredicateSplits(
           runs, [&](const AlignedRun& run) { return rep_set.count(run.repetition) > 0; },
           "every path type, reps " + FormatRepetitionList(reps), "the other reps")) {
    splits.push_back(std::move(s));
    break;  // the other direction would train on what was meant to be held out
  }

  std::printf("fitcal generalise: %s robot '%s', data set %s: %zu runs\n\n", robot.model.c_str(),
              robot.name.c_str(), options.logs.c_str(), runs.size());
  PrintSplitTableHeader();
  for (const GeneralisationSplit& split : splits) {
    PrintSplitRows(EvaluateSplit(*model, runs, split, fit_options, track_candidates));
    std::fflush(stdout);
  }
  if (options.leave_one_session_out) {
    std::vector<SplitScores> folds;
    for (const GeneralisationSplit& split : LeaveOneSessionOutSplits(runs, session_key)) {
      folds.push_back(EvaluateSplit(*model, runs, split, fit_options, track_candidates));
    }
    if (!folds.empty()) PrintLeaveOneSessionOut(folds);
  }
  return 0;
}

}  // namespace fitcal::tools
