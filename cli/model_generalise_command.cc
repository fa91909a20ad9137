#include "cli/model_generalise_command.h"
#include "cli/cli_validators.h"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <optional>

#include "cli/effect_list.h"
#include "cli/everyday_driving_table.h"
#include "models/model_registry.h"

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
    const bool written = c.is_fit && IsWrittenFit(c, /*final_pose_only=*/true);
    const std::string held = written ? std::to_string(c.held_directions) : "-";
    const std::string bound = written ? std::to_string(c.at_bound) : "-";
    std::printf("| %s -> %s | %s%s | %zu | %zu | %.4f | %.4f | %.3f | %.2f | %s | %s |\n",
                s.split.train_name.c_str(), s.split.test_name.c_str(), c.name.c_str(),
                c.usable ? "" : " (not converged)", s.split.train.size(), s.split.test.size(),
                c.train.cf, c.test.cf, c.test.mean_position_error_m,
                RadToDeg(c.test.mean_abs_heading_error_rad), held.c_str(), bound.c_str());
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
void PrintLeaveOneSessionOut(const GeneraliseOutcome& outcome) {
  std::printf(
      "\nleave-one-session-out (%zu sessions, each held out once)\n\n"
      "| candidate | folds | mean of the sessions' CF | CF over the held-out runs | pos. [m] | "
      "head. [deg] | folds with held directions | folds with a parameter at a bound |\n"
      "|---|---|---|---|---|---|---|---|\n",
      outcome.folds.size());
  for (const FoldSummary& s : outcome.fold_summary) {
    const std::string unusable =
        s.unusable_folds > 0 ? " (" + std::to_string(s.unusable_folds) + " not converged)" : "";
    std::printf("| %s | %d%s | %.4f | %.4f | %.3f | %.2f | %d | %d |\n", s.name.c_str(), s.folds,
                unusable.c_str(), s.mean_session_cf, s.run_cf, s.run_position_m,
                RadToDeg(s.run_heading_rad), s.folds_with_held_directions, s.folds_at_bound);
  }
  std::printf("\n| held-out session | runs |");
  for (const FoldSummary& s : outcome.fold_summary) std::printf(" %s |", s.name.c_str());
  std::printf("\n|---|---|");
  for (std::size_t k = 0; k < outcome.fold_summary.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (const SplitCalibration& calibrated : outcome.folds) {
    const SplitScores& fold = calibrated.scores;
    std::printf("| %s | %zu |", fold.split.test_name.c_str(), fold.split.test.size());
    for (const FoldSummary& s : outcome.fold_summary) {
      const auto c = std::find_if(fold.candidates.begin(), fold.candidates.end(),
                                  [&s](const CandidateScore& a) { return a.name == s.name; });
      if (c == fold.candidates.end()) {
        std::printf(" - |");  // not among this fold's candidates
      } else {
        std::printf(" %.4f |", c->test.cf);
      }
    }
    std::printf("\n");
  }
  std::printf("\n%s\n", FoldDecisionsLine(outcome.folds).c_str());
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

int RunGeneralise(const GeneraliseCommandOptions& flags) {
  const io::DatasetIndex index = OpenDataset(flags).index;
  const RobotModelPtr model = ReadRobotModelFile(index.robot_path);
  const Robot& robot = model->robot();
  GeneraliseRequest asked;
  asked.options = flags;  // the flags the library reads as given
  asked.dataset = flags.logs;
  if (const std::string refusal = ReadTying(flags, robot, &asked.tying); !refusal.empty()) {
    return Refuse(refusal);
  }
  if (!ParseSessionKey(flags.sessions, &asked.sessions)) return 2;
  asked.threads = flags.threads;
  asked.logs = LoadRuns(flags, index, robot).runs;
  const std::optional<EffectModel> effects = ReadEffectList(flags.effects, robot, "generalise");
  if (!effects) return 2;
  asked.effects = *effects;
  const GeneraliseRequest request = MakeGeneraliseRequest(std::move(asked), robot);

  std::printf("fitcal generalise: %s robot '%s', data set %s: %zu runs\n\n", robot.model.c_str(),
              robot.name.c_str(), flags.logs.c_str(), request.runs.size());
  if (!request.tying.empty()) {
    PrintTying(request.tying);
    std::printf("\n");
  }
  PrintSplitTableHeader();
  const GeneraliseOutcome outcome = Generalise(request, *model, [](const SplitCalibration& s) {
    PrintSplitRows(s.scores);
    std::fflush(stdout);
  });
  PrintDecisions(outcome.table);
  std::printf(
      "\neveryday driving on each split's held-out runs (ATE RMSE: each run's start pose "
      "aligned, no scale; drift per window of ground-truth path, validation/everyday_driving.h)\n");
  for (const auto& [title, comparison] : outcome.everyday_driving) {
    PrintEverydayDrivingTable(title, comparison, /*judge=*/true);
  }
  if (!outcome.folds.empty()) PrintLeaveOneSessionOut(outcome);
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
  return RunReportingErrors("fitcal", [&]() -> int { return RunGeneralise(options); });
}

}  // namespace fitcal::tools
