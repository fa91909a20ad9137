#include "cli/model_generalise_command.h"
#include "cli/cli_validators.h"

#include <cstdio>
#include <iostream>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

#include "calibrate/generalise_split.h"
#include "fit/effect_fit.h"
#include "fit/residual_choice.h"
#include "fit/run_split.h"
#include "fit/trajectory_split.h"
#include "models/model_registry.h"
#include "cli/effect_list.h"
#include "cli/everyday_driving_table.h"
#include "validation/generalisation.h"

namespace fitcal::tools {

namespace {

void PrintSplitTableHeader() {
  std::printf(
      "| trained on -> tested on | candidate | train runs | held-out runs | train CF | held-out "
      "CF | held-out pos. [m] | held-out head. [deg] | held directions | params at bound |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n");
}

void PrintSplitRows(const SplitScores& s) {
  for (const CandidateScore& c : s.candidates) {
    char held[16] = "-", bound[16] = "-";
    if (c.is_fit && IsWrittenFit(c, /*final_pose_only=*/true)) {
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

// What `fit` would write, or why it would refuse, on each split of the table.
void PrintDecisions(const std::vector<SplitCalibration>& calibrated) {
  std::printf(
      "\nwhat fit --residuals final-pose decides on each split (the result gate, never worse than "
      "the nominal on the held-out runs, no parameter on a bound; calibrate/calibrate.h)\n");
  for (const SplitCalibration& s : calibrated) {
    std::printf("  %s -> %s: %s\n", s.scores.split.train_name.c_str(),
                s.scores.split.test_name.c_str(), DecisionLine(s.outcome).c_str());
  }
}

// The summary over the folds, the held-out CF of every candidate per session, and what `fit`
// decides on the folds.
void PrintLeaveOneSessionOut(const std::vector<SplitCalibration>& calibrated) {
  std::vector<SplitScores> folds;
  for (const SplitCalibration& c : calibrated) folds.push_back(c.scores);
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
  std::printf("\n%s\n", FoldDecisionsLine(calibrated).c_str());
}

// What a leave-one-session-out session is (--sessions); false after one line on stderr.
bool ParseSessionKey(const std::string& text, SessionKey* key) {
  if (text == "label" || text == "repetition") {
    *key = text == "label" ? SessionKey::kLabel : SessionKey::kPathTypeAndRepetition;
    return true;
  }
  std::cerr << "fitcal: unknown --sessions '" << text << "' (available: label, repetition)\n";
  return false;
}

// What the candidates beyond nominal, closed forms and the final-pose fit need, kept alive while
// `candidates` points into it (never copied or moved once filled).
struct CandidateInputs {
  std::optional<std::vector<std::vector<Segment>>> checkpoints;
  std::vector<TrackRun> tracks;
  std::vector<const GroundTruthTrack*> ground_truth;  // one per run; also for everyday driving
  TrackCandidates candidates;
};

// Fills *in for --optiodom, --effects and, on dense ground-truth tracks, the track fit; false
// after one line on stderr.
bool PrepareCandidates(const GeneraliseCommandOptions& options, const Robot& robot,
                       const std::vector<RunLog>& logs, const std::vector<AlignedRun>& runs,
                       CandidateInputs* in) {
  if (options.optiodom) {
    in->checkpoints = OptiOdomCheckpoints(runs, logs);
    if (!in->checkpoints) {
      std::cerr << "fitcal: generalise --optiodom: " << options.logs
                << ": OptiOdom's method needs a ground-truth track (poses between each run's "
                   "start and end), and some run has only its ends\n";
      return false;
    }
    in->candidates.optiodom_checkpoints = &*in->checkpoints;
  }
  const std::optional<EffectModel> effect_list =
      ReadEffectList(options.effects, robot, "generalise");
  if (!effect_list) return false;
  if (!effect_list->empty()) {
    in->tracks = PrepareTrackRuns(logs, WheelChannelMask(robot));
    in->candidates.tracks = &in->tracks;
    in->candidates.effects = *effect_list;
  }
  // On dense ground-truth tracks (fit/residual_choice.h, as fit --residuals auto decides) the
  // track fit competes too.
  for (const RunLog& log : logs) in->ground_truth.push_back(&log.ground_truth);
  if (MeasureTrackDensity(runs, in->ground_truth).dense) {
    in->candidates.ground_truth = &in->ground_truth;
  }
  return true;
}

// The splits of the table: every ordered pair of path types (or the --train-trajectories
// selection against the rest, both ways), then the training repetitions of every path type
// against the others. nullopt after one line on stderr when the selection leaves a side empty.
std::optional<std::vector<GeneralisationSplit>> TableSplits(const GeneraliseCommandOptions& options,
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
      std::cerr << "fitcal: --train-trajectories '" << options.train_trajectories
                << "' must select some runs and leave some out\n";
      return std::nullopt;
    }
  } else {
    splits = PathTypeSplits(runs);
  }
  if (std::optional<GeneralisationSplit> s = RepetitionSplit(runs, options.train_reps)) {
    splits.push_back(std::move(*s));
  }
  return splits;
}

// The everyday-driving table `fit` prints (cli/everyday_driving_table.h), nominal against each
// fit of the split ("fit", "fit (track)": the calibrations `fit` writes, and their tied twins
// with --tie/--hold), on its held-out runs.
void PrintEverydayDrivingOfSplit(const RobotModelInterface& model,
                                 const std::vector<AlignedRun>& runs,
                                 const std::vector<const GroundTruthTrack*>& ground_truth,
                                 const SplitScores& scores, int threads) {
  std::vector<AlignedRun> held_out;
  std::vector<const GroundTruthTrack*> tracks;
  for (std::size_t i : scores.split.test) {
    held_out.push_back(runs[i]);
    tracks.push_back(ground_truth[i]);
  }
  const CandidateScore& nominal = scores.candidates.front();
  for (const CandidateScore& c : scores.candidates) {
    if (!IsWrittenFit(c)) continue;
    PrintEverydayDrivingTable(
        scores.split.train_name + " -> " + scores.split.test_name + ": " + c.name,
        CompareEverydayDriving(model, {nominal.name, nominal.parameters},
                               {c.name, c.parameters}, held_out, tracks, threads),
        /*judge=*/true);
  }
}

int Generalise(const GeneraliseCommandOptions& options) {
  const io::DatasetIndex index = OpenDataset(options).index;
  const RobotModelPtr model = ReadRobotModelFile(index.robot_path);
  const Robot& robot = model->robot();
  ParameterTying tying;
  if (const std::string refusal = ReadTying(options, robot, &tying); !refusal.empty()) {
    return Refuse(refusal);
  }
  SessionKey session_key = SessionKey::kLabel;
  if (!ParseSessionKey(options.sessions, &session_key)) return 2;
  const io::Dataset dataset = LoadRuns(options, index, robot);
  const std::vector<AlignedRun> runs = AlignRuns(dataset.runs);
  CandidateInputs inputs;
  if (!PrepareCandidates(options, robot, dataset.runs, runs, &inputs)) return 2;
  const std::optional<std::vector<GeneralisationSplit>> splits = TableSplits(options, runs);
  if (!splits) return 2;
  ModelFitOptions fit_options;
  fit_options.ceres.num_threads = options.threads;

  std::printf("fitcal generalise: %s robot '%s', data set %s: %zu runs\n\n", robot.model.c_str(),
              robot.name.c_str(), options.logs.c_str(), runs.size());
  if (!tying.empty()) {
    PrintTying(tying);
    std::printf("\n");
  }
  PrintSplitTableHeader();
  std::vector<SplitCalibration> calibrated;
  for (const GeneralisationSplit& split : *splits) {
    calibrated.push_back(CalibrateSplit(*model, dataset.runs, runs, split, fit_options,
                                        inputs.candidates, tying));
    PrintSplitRows(calibrated.back().scores);
    std::fflush(stdout);
  }
  PrintDecisions(calibrated);
  std::printf(
      "\neveryday driving on each split's held-out runs (ATE RMSE: each run's start pose "
      "aligned, no scale; drift per window of ground-truth path, validation/everyday_driving.h)"
      "\n");
  for (const SplitCalibration& s : calibrated) {
    PrintEverydayDrivingOfSplit(*model, runs, inputs.ground_truth, s.scores, options.threads);
  }
  if (options.leave_one_session_out) {
    std::vector<SplitCalibration> folds;
    for (const GeneralisationSplit& split : LeaveOneSessionOutSplits(runs, session_key)) {
      folds.push_back(CalibrateSplit(*model, dataset.runs, runs, split, fit_options,
                                     inputs.candidates, tying));
    }
    if (!folds.empty()) PrintLeaveOneSessionOut(folds);
  }
  return 0;
}

}  // namespace

void AddGeneraliseOptions(CLI::App& app, GeneraliseCommandOptions& o) {
  AddDatasetOptions(app, o);
  // A plain flag that clears the option: CLI11 prints a negated flag as "--no-loso{false}".
  app.add_flag_callback(
      "--no-loso", [&o] { o.leave_one_session_out = false; }, "Skip leave-one-session-out");
  app.add_option("--train-trajectories", o.train_trajectories,
                 "Train on labels matching (list or regular expression), test on the rest, "
                 "and the other way round");
  app.add_option("--effects", o.effects,
                 "Library effects: add the track fit alone and with these effects as candidates")
      ->delimiter(',');
  app.add_option("--train-reps", o.train_reps,
                 "Repetitions of every path type that train the split against the other "
                 "repetitions (default: the first half present)")
      ->check(RepetitionListValidator());
  app.add_option("--sessions", o.sessions,
                 "A leave-one-session-out session is a trajectory label (label) or a path "
                 "type + repetition number (repetition)")
      ->capture_default_str();
  app.add_flag("--optiodom", o.optiodom,
               "Also score OptiOdom's method (Sousa et al. 2022: position from the start every "
               "0.5 m of path) on the same splits");
  AddTyingFlags(app, o);
}

int RunGeneraliseCommand(const GeneraliseCommandOptions& options) {
  return RunReportingErrors("fitcal", [&]() -> int { return Generalise(options); });
}

}  // namespace fitcal::tools
