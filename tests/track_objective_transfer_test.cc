// The track objective chosen by transfer (validation/track_objective_transfer.h). The rule is
// tested with fits that return a marker per candidate and scores set per candidate and kind of
// run, the pooled measures computed here by hand; through the command line, `fit --track-heading
// auto` and `--weights auto` print the judgement, record it in the calibration's objective, and
// write what the chosen candidate's own flags write.
#include "validation/track_objective_transfer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "calibrate/choice_by_transfer.h"
#include "calibrate/track_residuals.h"
#include "models/diff_drive/diff_drive_trajectories.h"
#include "models/model_registry.h"
#include "odometry/text_format.h"
#include "tests/model_support.h"
#include "tests/test_files.h"
#include "tests/test_paths.h"
#include "sim/model_simulator.h"
#include "validation/trajectory_family.h"

namespace fitcal {
namespace {

// {cf, drift 2 m %, ate} per candidate and kind of run.
using Measures = std::array<double, 3>;
using Table = std::map<std::string, std::vector<Measures>>;

constexpr int kCircles = 3;  // runs of each kind: the circles weigh three times the square
constexpr int kSquares = 1;
constexpr int kWindowsPerRun = 10;

RunSplit CirclesAndSquares() {
  RunSplit split;
  for (int rep = 1; rep <= kCircles; ++rep) split.training.push_back(testing::LabelledRun("circular_1", rep));
  for (int rep = 1; rep <= kSquares; ++rep) split.training.push_back(testing::LabelledRun("square_1", rep));
  return split;
}

const std::vector<TrackObjective> kFourCandidates = {
    {false, TrackHeading::kFromStart},
    {true, TrackHeading::kFromStart},
    {false, TrackHeading::kIncrements},
    {true, TrackHeading::kIncrements}};

// `table` judged by `judge` (by transfer unless given), the fits a marker per candidate.
TrackObjectiveJudgement Judge(const Table& table, const RunSplit& split,
                              const std::vector<TrackObjective>& candidates = kFourCandidates,
                              bool usable = true,
                              decltype(&JudgeTrackObjectivesByTransfer) judge =
                                  &JudgeTrackObjectivesByTransfer) {
  const FitByTrackObjective fit_on =
      [&](const TrackObjective& o, const std::vector<AlignedRun>&)
      -> std::optional<std::vector<double>> {
    if (!usable) return std::nullopt;
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      if (candidates[c].estimate_weights == o.estimate_weights && candidates[c].heading == o.heading)
        return std::vector<double>{static_cast<double>(c)};
    }
    return std::nullopt;
  };
  const ScoreOnRuns score = [&](const std::vector<double>& p, const std::vector<AlignedRun>& runs) {
    const Measures& m =
        table.at(TrajectoryFamily(runs.front().trajectory))[static_cast<std::size_t>(p[0])];
    EverydayDrivingMetrics e;
    e.runs = static_cast<int>(runs.size());
    e.cf = m[0];
    e.drift.push_back({2.0, kWindowsPerRun * e.runs, m[1], 0.0});
    e.mean_ate_rmse_m = m[2];
    return e;
  };
  return judge(candidates, split, fit_on, score);
}

// Candidate 2 is worse than the default on the square (1 run) and better on the circles (3 runs):
// pooled, every run counting once, it is lower on all three measures and replaces the default,
// though it would lose a vote per kind of run. Candidate 1 is lower on CF and ATE but not on the
// drift: it never replaces the default (no trade of one measure for another).
TEST(TrackObjectiveTransfer, PoolsEveryJudgedRunAndReplacesTheDefaultOnlyWhenLowerOnAllThree) {
  const Table table = {
      {"circular", {{0.100, 1.00, 0.050}, {0.050, 1.01, 0.030}, {0.090, 0.90, 0.045}, {0.2, 2, 0.1}}},
      {"square", {{0.100, 1.00, 0.050}, {0.050, 1.01, 0.030}, {0.110, 1.10, 0.055}, {0.2, 2, 0.1}}}};
  const TrackObjectiveJudgement j = Judge(table, CirclesAndSquares());
  ASSERT_TRUE(j.judged);
  EXPECT_FALSE(j.on_free_driving);
  ASSERT_EQ(j.pooled.size(), 4u);
  // By hand: (3 * 0.090 + 1 * 0.110) / 4 = 0.095; drift (30 * 0.90 + 10 * 1.10) / 40 = 0.95;
  // ATE (3 * 0.045 + 0.055) / 4 = 0.0475.
  EXPECT_NEAR(j.pooled[2].cf, 0.095, 1e-12);
  EXPECT_NEAR(j.pooled[2].drift_percent, 0.95, 1e-12);
  EXPECT_NEAR(j.pooled[2].ate_rmse_m, 0.0475, 1e-12);
  EXPECT_EQ(j.pooled[2].runs, kCircles + kSquares);
  EXPECT_EQ(j.pooled[2].drift_windows, kWindowsPerRun * (kCircles + kSquares));
  EXPECT_EQ(j.chosen, 2);
  EXPECT_EQ(j.judged_on, "circular (3), square (1)");
  const std::string text = TrackObjectiveChoiceText(j);
  EXPECT_TRUE(testing::Has(text, "weights fixed, heading increments chosen by transfer")) << text;
  EXPECT_TRUE(testing::Has(text, "CF 0.1000 -> 0.0950")) << text;
  const std::vector<std::string> lines = TrackObjectiveJudgementLines(j);
  ASSERT_EQ(lines.size(), 2u + 4u + 1u);
  EXPECT_TRUE(testing::Has(lines[2], "weights fixed, heading from-start (default)")) << lines[2];
  EXPECT_TRUE(testing::Has(lines.back(), "weights fixed, heading increments chosen")) << lines.back();
}

// Two candidates lower on all three: the one with the lower pooled CF.
TEST(TrackObjectiveTransfer, OfSeveralBetterCandidatesTheLowestPooledCfWins) {
  const Table table = {
      {"circular", {{0.100, 1.00, 0.050}, {0.080, 0.99, 0.049}, {0.090, 0.90, 0.040}, {0.2, 2, 0.1}}},
      {"square", {{0.100, 1.00, 0.050}, {0.080, 0.99, 0.049}, {0.090, 0.90, 0.040}, {0.2, 2, 0.1}}}};
  EXPECT_EQ(Judge(table, CirclesAndSquares()).chosen, 1);
}

// Lower CF and ATE but a higher drift, or equal on one measure: the default is kept and said.
TEST(TrackObjectiveTransfer, KeepsTheDefaultWhenNoCandidateIsLowerOnEveryMeasure) {
  const Table table = {
      {"circular", {{0.100, 1.00, 0.050}, {0.050, 1.01, 0.030}, {0.090, 1.00, 0.040}, {0.2, 2, 0.1}}},
      {"square", {{0.100, 1.00, 0.050}, {0.050, 1.01, 0.030}, {0.090, 1.00, 0.040}, {0.2, 2, 0.1}}}};
  const TrackObjectiveJudgement j = Judge(table, CirclesAndSquares());
  ASSERT_TRUE(j.judged);
  EXPECT_EQ(j.chosen, 0);
  EXPECT_TRUE(testing::Has(TrackObjectiveChoiceText(j), "from-start kept by transfer"));
  EXPECT_TRUE(testing::Has(TrackObjectiveJudgementLines(j).back(), "no other is lower on all three"));
}

// Nothing to choose, nothing to judge on, or a fit that is not usable: not judged, the default.
TEST(TrackObjectiveTransfer, NotJudgedWithoutCandidatesKindsOrUsableFits) {
  const Table table = {{"circular", {{0.1, 1, 0.05}, {0.05, 0.5, 0.01}, {0.1, 1, 0.05}, {0.1, 1, 0.05}}},
                       {"square", {{0.1, 1, 0.05}, {0.05, 0.5, 0.01}, {0.1, 1, 0.05}, {0.1, 1, 0.05}}}};
  EXPECT_FALSE(Judge(table, CirclesAndSquares(), {kFourCandidates[0]}).judged);
  RunSplit one_kind;
  for (int rep = 1; rep <= 3; ++rep) one_kind.training.push_back(testing::LabelledRun("circular_1", rep));
  EXPECT_FALSE(Judge(table, one_kind).judged);
  const TrackObjectiveJudgement unusable = Judge(table, CirclesAndSquares(), kFourCandidates, false);
  EXPECT_FALSE(unusable.judged);
  EXPECT_EQ(unusable.chosen, 0);
  EXPECT_TRUE(TrackObjectiveJudgementLines(unusable).empty());
  EXPECT_EQ(TrackObjectiveChoiceText(unusable), "");
}

// Held-out free driving judges alone (one fold, all training runs fitted).
// The two choices by transfer judge the default candidate's fold fits on the same runs: through
// FoldFits::ScoredOnce each fit is scored once per set of runs, the second judgement reads the
// first one's measures (the same numbers: a score is a function of the parameters and the runs).
TEST(TrackObjectiveTransfer, FoldFitsScoreEachFitOnceOnEachSetOfRuns) {
  const RunSplit split = CirclesAndSquares();
  int scored = 0;
  FoldFits fold_fits;
  const ScoreOnRuns score = fold_fits.ScoredOnce(
      [&](const std::vector<double>& p, const std::vector<AlignedRun>& runs) {
        ++scored;
        EverydayDrivingMetrics e;
        e.runs = static_cast<int>(runs.size());
        e.cf = p[0] + 0.5 * scored;  // differs per call: a second scoring would show
        return e;
      });
  const double first = score({1.0}, split.training).cf;
  EXPECT_EQ(score({1.0}, split.training).cf, first);
  EXPECT_EQ(scored, 1);
  score({1.0}, {split.training.front()});  // other runs
  score({std::nextafter(1.0, 2.0)}, split.training);  // another fit, one ulp away
  EXPECT_EQ(scored, 3);
  // A run's later time block keeps its id (validation/time_blocks.h): other runs all the same.
  std::vector<AlignedRun> later_blocks = split.training;
  for (AlignedRun& run : later_blocks) run.t_start_s += 1.0;
  score({1.0}, later_blocks);
  EXPECT_EQ(scored, 4);
  // Both judgements on these folds (2 kinds of run): the default's two fold fits scored once.
  const FitCandidate fit_on = [](int c, const std::vector<AlignedRun>& training) {
    return std::optional<std::vector<double>>(
        std::vector<double>{10.0 * c + static_cast<double>(training.size())});
  };
  const std::vector<TransferFold> folds = MakeTransferFolds(split).folds;
  ASSERT_EQ(folds.size(), 2u);
  scored = 0;
  ASSERT_TRUE(FitAndScoreFolds(folds, 2, fit_on, score));
  EXPECT_EQ(scored, 4);
  ASSERT_TRUE(FitAndScoreFolds(folds, 3, fit_on, score));  // candidates 0 and 1 again, and 2
  EXPECT_EQ(scored, 6);
}

TEST(TrackObjectiveTransfer, HeldOutFreeDrivingIsTheOneFold) {
  RunSplit split = CirclesAndSquares();
  split.validation.push_back(testing::LabelledRun("free_1", 1));
  const Table table = {{"free", {{0.1, 1, 0.05}, {0.2, 2, 0.1}, {0.09, 0.9, 0.04}, {0.2, 2, 0.1}}}};
  const TrackObjectiveJudgement j = Judge(table, split);
  ASSERT_TRUE(j.judged);
  EXPECT_TRUE(j.on_free_driving);
  EXPECT_EQ(j.judged_on, "free (1)");
  EXPECT_EQ(j.chosen, 2);
}

// --weights auto: the weights are judged on the held-out runs (one fold: every training run
// fitted, every held-out run judged, whatever its kind), by the same pooled rule; nothing to judge
// without held-out runs.
TEST(TrackObjectiveTransfer, WeightsAreJudgedOnTheHeldOutRunsByThePooledRule) {
  RunSplit split = CirclesAndSquares();
  split.validation = {testing::LabelledRun("circular_1", 4), testing::LabelledRun("circular_1", 5)};
  const std::vector<TrackObjective> weights = {{false, TrackHeading::kIncrements},
                                               {true, TrackHeading::kIncrements}};
  // Lower on all three on the held-out circles: chosen; higher drift (below): kept.
  const Table better = {{"circular", {{0.10, 1.0, 0.050}, {0.09, 0.9, 0.040}}}};
  const TrackObjectiveJudgement j =
      Judge(better, split, weights, true, &JudgeTrackWeightsOnHeldOutRuns);
  ASSERT_TRUE(j.judged);
  EXPECT_TRUE(j.on_held_out_runs);
  EXPECT_EQ(j.pooled[1].runs, 2);  // the held-out runs, not the training runs' kinds
  EXPECT_EQ(j.chosen, 1);
  const std::string text = TrackObjectiveChoiceText(j);
  EXPECT_TRUE(testing::Has(text, "; weights estimated, heading increments chosen on the held-out "
                                 "runs (2: CF 0.1000 -> 0.0900, drift 2 m 1.000 -> 0.900 %"))
      << text;
  const std::vector<std::string> lines = TrackObjectiveJudgementLines(j);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0], "track weights fitted on every training run, judged on the held-out runs (2):");
  const Table drift_worse = {{"circular", {{0.10, 1.0, 0.050}, {0.09, 1.1, 0.040}}}};
  const TrackObjectiveJudgement kept =
      Judge(drift_worse, split, weights, true, &JudgeTrackWeightsOnHeldOutRuns);
  EXPECT_EQ(kept.chosen, 0);
  EXPECT_TRUE(testing::Has(TrackObjectiveChoiceText(kept), "increments kept on the held-out runs (2"));
  EXPECT_FALSE(
      Judge(better, CirclesAndSquares(), weights, true, &JudgeTrackWeightsOnHeldOutRuns).judged);
}

// A simulated differential drive (every length 2 % large, circles and squares, the ground truth
// with white noise): the runs, and through the command line their data set.
std::vector<sim::ModelSimulatedRun> SimulatedLoopRuns() {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  sim::SimulationOptions o;
  o.wheel_rate_sigma_rad_s = 0.01;
  o.ground_truth_period_s = 0.05;
  std::vector<double> truth = model->robot().nominal;
  for (double& v : truth) v *= 1.02;
  sim::DiffDriveTrajectoryOptions shapes;
  shapes.circle_laps = 1.25;
  std::vector<sim::ModelSimulatedRun> runs = sim::SimulateRuns(
      *model, truth, sim::DiffDriveCalibrationTrajectories(2, shapes), o);
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (sim::ModelSimulatedRun& run : runs) {
    std::vector<Pose2d>& poses = run.log.ground_truth.world_T_robot;
    for (std::size_t i = 1; i < poses.size(); ++i) {
      poses[i].x += 0.003 * normal(rng);
      poses[i].y += 0.003 * normal(rng);
      poses[i].theta += 0.01 * normal(rng);
    }
  }
  return runs;
}

std::string SimulatedLoops(const testing::TempDir& tmp) {
  const std::vector<sim::ModelSimulatedRun> runs = SimulatedLoopRuns();
  const std::string dir = tmp.Path("loops");
  sim::WriteSimulatedDataset(dir, FindModel("diff_drive")->example_yaml, runs);
  return dir;
}

// The folds of `fit --residuals auto` are judgement fits (FitMethodSettings::judgement_fit: no
// covariance, the held fit started from the projection of the fit without the hold, drift scored
// at 2 m only). On the simulated loops the truth makes the choice known: every length is 2 %
// large, a common scale that a closed loop's final pose cannot see (docs/everyday_driving.md), so
// the final-pose fit of one kind of loop holds that direction at the nominal and transfers worse
// than the track, which sees it. The judgement fits choose the track, as the converged refits
// with every measure (judgement_fit off, from the same start) do, and score each fold alike: both
// are minima of the same problem, so the table's CF, drift and ATE are the refits' to the
// decimals it prints.
TEST(TrackObjectiveTransfer, JudgementFitsChooseWhatConvergedRefitsChooseWhereTheTruthIsKnown) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  RunSplit split;
  for (const sim::ModelSimulatedRun& run : SimulatedLoopRuns()) split.training.push_back(AlignRun(run.log));
  const FitMethod& method = *FindFitMethod("ceres");
  FitMethodSettings settings;
  settings.threads = 1;
  settings.estimate_weights = false;
  settings.residuals_auto = true;
  std::optional<TrackFitData> data;
  ASSERT_EQ(PrepareTrackResiduals(method.name, split.training, &settings, &data), "");
  ASSERT_EQ(settings.residuals, ResidualKind::kTrack);
  const FitMethodSettings proposed = settings;
  std::optional<ModelFitMethodOutcome> full;
  FoldFits fold_fits;
  const std::vector<std::string> lines = ChooseResidualsByTransfer(
      method, 1, *model, split, &settings, &data, &full, &fold_fits);
  ASSERT_FALSE(lines.empty());
  std::string table;
  for (const std::string& line : lines) table += line + "\n";
  EXPECT_EQ(settings.residuals, ResidualKind::kTrack) << table;
  ASSERT_TRUE(full.has_value());

  // The same folds refitted to convergence with everything a written fit computes.
  std::vector<bool> held_a_direction;
  const FitByKind converged = [&](ResidualKind kind, const std::vector<AlignedRun>& training) {
    FitMethodSettings s = proposed;
    s.residuals = kind;
    s.residuals_auto = false;
    s.start = full->fit.parameters;
    std::optional<TrackFitData> part_data;
    EXPECT_EQ(PrepareTrackResiduals(method.name, training, &s, &part_data), "");
    const ModelFitResult fit = method.run_model(training, *model, s).fit;
    EXPECT_TRUE(fit.usable) << fit.message;
    if (kind == ResidualKind::kFinalPose) held_a_direction.push_back(!fit.held_directions.empty());
    return std::optional<std::vector<double>>(fit.parameters);
  };
  const ResidualKindJudgement reference = JudgeResidualKindsByTransfer(
      ResidualKind::kTrack, ResidualKind::kFinalPose, split, converged,
      EverydayDrivingScore(*model, 1, EverydayDriftLengths()));
  ASSERT_TRUE(reference.judged);
  EXPECT_EQ(reference.chosen, ResidualKind::kTrack);
  // The case the projection serves: a final-pose fold holds the common scale.
  EXPECT_NE(std::count(held_a_direction.begin(), held_a_direction.end(), true), 0);
  // The judgement's table, row by row, against the converged refits' numbers.
  ASSERT_EQ(lines.size(), 4 + reference.comparisons.size()) << table;
  for (std::size_t f = 0; f < reference.comparisons.size(); ++f) {
    const KindComparison& c = reference.comparisons[f];
    const DriftAtLength* p = DriftAt(c.proposed, kTransferDriftLength_m);
    const DriftAtLength* a = DriftAt(c.alternative, kTransferDriftLength_m);
    ASSERT_TRUE(p != nullptr && a != nullptr);
    const std::string row = lines[2 + f];
    SCOPED_TRACE(row);
    EXPECT_TRUE(testing::Has(row, StrFormat("%.4f | %-8.4f", c.proposed.cf, c.alternative.cf)));
    EXPECT_TRUE(testing::Has(row, StrFormat("%.3f | %.3f", p->translation_percent,
                                            a->translation_percent)));
    EXPECT_TRUE(testing::Has(row, StrFormat("%.4f | %.4f", c.proposed.mean_ate_rmse_m,
                                            c.alternative.mean_ate_rmse_m)));
  }
}

// Everything of a calibration YAML but its `objective:` line (which records how it was chosen).
std::string WithoutObjective(const std::string& yaml) {
  std::string out, line;
  for (char c : yaml) {
    line += c;
    if (c != '\n') continue;
    if (!testing::Has(line, "objective:")) out += line;
    line.clear();
  }
  return out + line;
}

// The default (--track-heading auto) judges the two headings, prints the table and the reason,
// records the choice in the objective, and writes exactly what the chosen heading's own flag
// writes; --weights auto adds the estimated weights as candidates; an explicit heading, or a
// sigma given with --weights auto, judges nothing.
TEST(TrackObjectiveTransfer, FitCommandChoosesRecordsAndWritesTheChosenObjective) {
  testing::TempDir tmp;
  const std::string fit =
      "fit --logs " + SimulatedLoops(tmp) + " --residuals track --threads 1 --train-reps 1-99";
  const testing::FitcalRun automatic = testing::RunFitcal(tmp, fit + " --out " + tmp.Path("a.yaml"));
  ASSERT_EQ(automatic.exit_code, 0) << automatic.out << automatic.err;
  EXPECT_TRUE(testing::Has(automatic.out, "track objectives judged on runs of a kind they were "
                                          "not fitted on, pooled over"))
      << automatic.out;
  EXPECT_FALSE(testing::Has(automatic.out, "weights estimated, heading")) << automatic.out;
  const bool increments = testing::Has(automatic.out, "heading increments chosen:");
  EXPECT_TRUE(increments || testing::Has(automatic.out, "heading from-start kept:"))
      << automatic.out;
  const std::string a = testing::ReadFileBytes(tmp.Path("a.yaml"));
  EXPECT_TRUE(testing::Has(a, increments ? "heading increments chosen by transfer (pooled over"
                                         : "heading from-start kept by transfer (pooled over"))
      << a;

  const std::string heading = increments ? "increments" : "from-start";
  const testing::FitcalRun given = testing::RunFitcal(
      tmp, fit + " --track-heading " + heading + " --out " + tmp.Path("b.yaml"));
  ASSERT_EQ(given.exit_code, 0) << given.out << given.err;
  EXPECT_FALSE(testing::Has(given.out, "track objectives judged")) << given.out;
  EXPECT_EQ(WithoutObjective(a), WithoutObjective(testing::ReadFileBytes(tmp.Path("b.yaml"))));

  // --weights auto (the default): nothing held out here, so the weights stay fixed, said; with
  // the second repetitions held out they are judged there.
  EXPECT_TRUE(testing::Has(automatic.out, "track weights fixed: no held-out run")) << automatic.out;
  const testing::FitcalRun held_out = testing::RunFitcal(
      tmp, "fit --logs " + tmp.Path("loops") + " --residuals track --threads 1 --train-reps 1 "
           "--no-output");
  ASSERT_EQ(held_out.exit_code, 0) << held_out.out << held_out.err;
  EXPECT_TRUE(testing::Has(held_out.out, "track weights fitted on every training run, judged on "
                                         "the held-out runs (6):\n"))
      << held_out.out;
  EXPECT_TRUE(testing::Has(held_out.out, "  weights estimated, heading ")) << held_out.out;

  const testing::FitcalRun sigma = testing::RunFitcal(
      tmp, fit + " --weights auto --position-sigma-m 1 --track-heading from-start --no-output");
  ASSERT_EQ(sigma.exit_code, 0) << sigma.out << sigma.err;
  EXPECT_FALSE(testing::Has(sigma.out, "track objectives judged")) << sigma.out;

  const testing::FitcalRun bad = testing::RunFitcal(tmp, fit + " --track-heading sideways --no-output");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(testing::Has(bad.err, "(available: from-start, increments, auto)")) << bad.err;
  const testing::FitcalRun bad_weights = testing::RunFitcal(tmp, fit + " --weights guessed --no-output");
  EXPECT_NE(bad_weights.exit_code, 0);
  EXPECT_TRUE(testing::Has(bad_weights.err, "--weights")) << bad_weights.err;
}

// On the real OptiOdom loops (../shared; skipped without it), a plain `fit`: the differential
// drive's circles and squares say the heading increments transfer better (pooled over both kinds:
// CF, drift and ATE lower; docs/everyday_driving.md), omni3's keep the heading from the start
// (increments are worse on all three there). The differential drive's calibration is the one
// --track-heading increments writes.
TEST(TrackObjectiveTransfer, RealLoopsChooseIncrementsOnTheDiffDriveAndKeepTheStartOnOmni3) {
  const std::string root = FITCAL_SHARED_DIR + "/data/optiodom/";
  if (!std::filesystem::is_directory(root + "diff/circular")) GTEST_SKIP() << "no " << root;
  testing::TempDir tmp;
  for (const std::string robot : {"diff", "omni3"}) {
    const std::string data = tmp.Path(robot);
    const auto import = testing::RunFitcal(tmp, "import optiodom " + root + robot + "/circular/* " +
                                                    root + robot + "/square/* --out " + data);
    ASSERT_EQ(import.exit_code, 0) << import.err;
    const std::string cal = tmp.Path(robot + ".yaml");
    const auto fit = testing::RunFitcal(tmp, "fit --logs " + data + " --out " + cal);
    ASSERT_EQ(fit.exit_code, 0) << fit.out << fit.err;
    if (robot == "omni3") {
      EXPECT_TRUE(testing::Has(fit.out, "weights fixed, heading from-start kept:")) << fit.out;
      continue;
    }
    EXPECT_TRUE(testing::Has(fit.out, "weights fixed, heading increments chosen:")) << fit.out;
    const auto given = testing::RunFitcal(
        tmp, "fit --logs " + data + " --track-heading increments --out " + tmp.Path("given.yaml"));
    ASSERT_EQ(given.exit_code, 0) << given.out << given.err;
    EXPECT_EQ(WithoutObjective(testing::ReadFileBytes(cal)),
              WithoutObjective(testing::ReadFileBytes(tmp.Path("given.yaml"))));
  }
}

}  // namespace
}  // namespace fitcal
