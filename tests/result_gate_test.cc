// The result gate (fit/result_gate.h) and the never-worse judgement (validation/never_worse.h).
// The gate keeps the nominal unless a candidate is strictly better on the judging runs. The
// never-worse judgement: a calibration is refused on a measure only
// when it is worse than the nominal beyond the scatter the runs' repetitions show. Checked here on
// per-run values drawn by a generator of its own (not fitcal's replay): each run's value is its
// trajectory's level times (1 + sigma * a standard normal), the calibration's level a factor
// (1 + shift) of the nominal's. The rates the rule promises are counted over many draws and held
// to binomial tolerances; the issue's two refusals of clean robots are replayed with their
// numbers; and the margin is checked against a hand computation of the formula.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fit/result_gate.h"
#include "fit/statistics.h"
#include "tests/model_support.h"
#include "validation/never_worse.h"

namespace fitcal {
namespace {

// Runs of one family: `labels` trajectories (family + index), `reps` repetitions each.
std::vector<AlignedRun> Family(const std::string& family, int labels, int reps) {
  std::vector<AlignedRun> runs;
  for (int l = 1; l <= labels; ++l) {
    for (int r = 1; r <= reps; ++r) {
      runs.push_back(testing::LabelledRun(family + std::to_string(l), r));
    }
  }
  return runs;
}

// The never-worse judgement of a CF per run alone (JudgeNeverWorse without ATE or drift).
std::vector<NeverWorseJudgement> JudgeNeverWorseOnCf(const std::vector<AlignedRun>& runs,
                                                     const std::vector<double>& nominal_cf,
                                                     const std::vector<double>& calibrated_cf) {
  EverydayDrivingMetrics nominal, calibrated;
  nominal.per_run_cf = nominal_cf;
  calibrated.per_run_cf = calibrated_cf;
  return JudgeNeverWorse(runs, nominal, calibrated);
}

// The generator: one value per run, level_of_label * (1 + shift) * (1 + sigma * N(0, 1)).
std::vector<double> Draw(const std::vector<AlignedRun>& runs, double sigma, double shift,
                         std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> v;
  for (const AlignedRun& run : runs) {
    const double level = 0.01 * (1.0 + 0.1 * static_cast<double>(run.trajectory.size() % 5));
    v.push_back(level * (1.0 + shift) * (1.0 + sigma * normal(*rng)));
  }
  return v;
}

int Refusals(const std::vector<NeverWorseJudgement>& judgements) {
  int n = 0;
  for (const NeverWorseJudgement& j : judgements) n += j.Worse() ? 1 : 0;
  return n;
}

// Candidates scored by a table (the gate's effect_cf) so that the choice alone is tested: each
// carries one neutral effect, which routes it to the table instead of a replay.
GateDecision Choose(const std::vector<double>& cf_of_candidate) {
  std::vector<CalibrationCandidate> candidates;
  for (std::size_t i = 0; i < cf_of_candidate.size(); ++i) {
    candidates.push_back({i == 0 ? "nominal" : "fit " + std::to_string(i), {double(i)}, true,
                          {effects::EffectValue{}}});
  }
  const EffectCandidateCf table = [&](const CalibrationCandidate& c,
                                      const std::vector<AlignedRun>&) {
    return cf_of_candidate[static_cast<std::size_t>(c.parameters[0])];
  };
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  return SelectCalibration(*model, candidates, {testing::LabelledRun("square", 1)},
                           {testing::LabelledRun("square", 2)}, 1, table);
}

// The nominal is kept when every candidate is worse, and on a tie; a strictly better one wins.
// (A gate that never kept the nominal passed every test before: issue 43 item 5.)
TEST(ResultGate, KeepsTheNominalUnlessACandidateIsStrictlyBetter) {
  EXPECT_EQ(Choose({1.0, 2.0, 1.5}).selected, 0);
  EXPECT_FALSE(Choose({1.0, 2.0, 1.5}).improves_on_nominal());
  EXPECT_EQ(Choose({1.0, 1.0}).selected, 0);  // a tie: a calibration must earn its place
  EXPECT_EQ(Choose({1.0, 2.0, 0.5, 0.7}).selected, 2);
  EXPECT_TRUE(Choose({1.0, 0.9}).judged_on_held_out);
}

// A parameter on its bound is named with its value and bounds; none, no refusal.
TEST(ResultGate, AtBoundRefusalNamesTheParameter) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  const Robot& robot = model->robot();
  std::vector<bool> at_bound(robot.parameters.size(), false);
  EXPECT_EQ(AtBoundRefusal(robot, "ceres", robot.nominal, at_bound), "");
  std::vector<double> p = robot.nominal;
  p[0] = robot.bounds[0].hi;
  at_bound[0] = true;
  const std::string refusal = AtBoundRefusal(robot, "ceres", p, at_bound);
  EXPECT_NE(refusal.find(robot.parameters[0].name), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("--bounds-widened"), std::string::npos) << refusal;
}

// A pick on a bound gives way to the best other candidate that beats the nominal with nothing on
// a bound; a candidate with effects (their own test chose among them), one on a bound itself, one
// not usable and one that only ties the nominal do not take its place.
TEST(ResultGate, APickOnABoundGivesWayToTheBestInsideTheBounds) {
  std::vector<CalibrationCandidate> candidates = {
      {"nominal", {0.0}}, {"closed form", {1.0}}, {"other fit", {2.0}}, {"ceres", {3.0}},
      {"with effects", {4.0}, true, {effects::EffectValue{}}}};
  GateDecision decision;
  decision.selected = 3;
  decision.cf = {1.0, 0.5, 0.4, 0.3, 0.2};
  std::vector<bool> on_a_bound = {false, false, false, true, false};
  const auto at_bound = [&](int i) { return std::vector<bool>{false, on_a_bound[i]}; };
  EXPECT_EQ(BestCandidateInsideTheBounds(candidates, decision, at_bound), 2);
  on_a_bound[2] = true;
  EXPECT_EQ(BestCandidateInsideTheBounds(candidates, decision, at_bound), 1);
  candidates[1].usable = false;
  EXPECT_EQ(BestCandidateInsideTheBounds(candidates, decision, at_bound), 0);
  candidates[1].usable = true;
  decision.cf[1] = 1.0;  // a tie with the nominal earns no place
  EXPECT_EQ(BestCandidateInsideTheBounds(candidates, decision, at_bound), 0);
}

// The t quantile the margins use, against two table values (Student t, one-sided: t_{0.95, 2} =
// 2.920, t_{0.995, 10} = 3.169; any statistics table).
TEST(NeverWorse, StudentQuantileMatchesTheTable) {
  EXPECT_NEAR(stats::StudentTUpperQuantile(0.05, 2), 2.920, 1e-3);
  EXPECT_NEAR(stats::StudentTUpperQuantile(0.005, 10), 3.169, 1e-3);
}

// The margin by hand: two labels of two repetitions, values 1 +- 0.1 for the nominal and 1.1 +-
// 0.1 for the calibration: relative deviations 0.1 and 1/11 per run, 4 dof, s^2 = (4 x 0.01 + 4 x
// (1/11)^2) / 4; margin = t_{0.05, 4} x s x 1.05 x sqrt(2 / 4).
TEST(NeverWorse, MarginIsTheFormula) {
  const std::vector<std::string> labels = {"a", "a", "b", "b"};
  const std::vector<double> ones(4, 1.0);
  const NeverWorseJudgement j = JudgeMeasure("CF", "runs", labels, ones, {0.9, 1.1, 0.9, 1.1},
                                             {1.0, 1.2, 1.0, 1.2}, {}, 1);
  const double s = std::sqrt((4 * 0.01 + 4 * (1.0 / 121.0)) / 4.0);
  EXPECT_EQ(j.spread.dof, 4);
  EXPECT_NEAR(j.spread.relative_sd, s, 1e-12);
  EXPECT_NEAR(j.margin, 2.1318 * s * 1.05 * std::sqrt(0.5), 1e-4);  // t_{0.95, 4} = 2.1318
  EXPECT_FALSE(j.Worse());  // 1.1 against 1.0: 0.1 inside a margin of 0.15
  EXPECT_NE(j.Description().find("margin"), std::string::npos);
}

// Issue 42: the circles-only diff fit's squares drifted 13 % more at 1 m (0.740 -> 0.836 %) inside
// the margin of their scatter; written (issue 43: no refusal on noise), but said. The numbers of
// MarginIsTheFormula, two labels of two repetitions: +10 % on every run, inside the margin.
TEST(NeverWorse, ARiseWithinTheScatterIsSaidNotRefused) {
  const std::vector<AlignedRun> runs = {
      testing::LabelledRun("a", 1), testing::LabelledRun("a", 2), testing::LabelledRun("b", 1),
      testing::LabelledRun("b", 2)};
  const std::vector<double> nominal = {0.9, 1.1, 0.9, 1.1};
  const std::vector<NeverWorseJudgement> j =
      JudgeNeverWorseOnCf(runs, nominal, {1.0, 1.2, 1.0, 1.2});
  EXPECT_EQ(Refusals(j), 0);
  const std::vector<std::string> lines = NeverWorseWithinScatter("ceres", j);
  ASSERT_EQ(lines.size(), 3u);  // all runs, 'a', 'b'
  EXPECT_NE(lines[0].find("'ceres' is worse than the nominal on the held-out runs (4), within the "
                          "runs' scatter: CF 1 -> 1.1 (+10.0 %), within the margin "),
            std::string::npos)
      << lines[0];
  EXPECT_NE(lines[1].find("held-out 'a' runs (2)"), std::string::npos) << lines[1];
  EXPECT_EQ(NeverWorseRowNotes(j).at("CF").rfind("worse, within the scatter: margin ", 0), 0u);
  // +4 % is under the report's regression tolerance (5 %): the row says it rose, no warning.
  const std::vector<NeverWorseJudgement> small =
      JudgeNeverWorseOnCf(runs, nominal, {0.936, 1.144, 0.936, 1.144});
  EXPECT_TRUE(NeverWorseWithinScatter("ceres", small).empty());
  EXPECT_EQ(NeverWorseRowNotes(small).count("CF"), 1u);
  // Beyond the margin the row says so (and the refusal line is NeverWorseRefusals').
  const std::vector<NeverWorseJudgement> big =
      JudgeNeverWorseOnCf(runs, nominal, {2.7, 3.3, 2.7, 3.3});
  EXPECT_TRUE(NeverWorseWithinScatter("ceres", big).empty());
  EXPECT_EQ(NeverWorseRowNotes(big).at("CF").rfind("worse beyond the scatter: margin ", 0), 0u);
}

// No run repeats anything: margin 0, said so, and any rise refuses (the rule of before).
TEST(NeverWorse, WithoutRepetitionsTheMarginIsZeroAndSaidSo) {
  const std::vector<AlignedRun> runs = {testing::LabelledRun("circle", 1),
                                        testing::LabelledRun("square", 1)};
  const std::vector<NeverWorseJudgement> j = JudgeNeverWorseOnCf(runs, {1.0, 1.0}, {1.0, 1.01});
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j[0].margin, 0.0);
  EXPECT_GE(Refusals(j), 1);
  const std::vector<std::string> lines = NeverWorseRefusals("ceres", j);
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines[0].find("the noise is not measured"), std::string::npos) << lines[0];
}

// The issue's refusals of clean simulated robots (issue 43): spinR, 2 held-out runs, CF 0.00319512
// -> 0.00360461, and G, 12 held-out runs (G1-G12, one each), 0.00728501 -> 0.00737964, with a
// run-to-run scatter of 10 % (the simulator's 2 mm / 0.2 deg ground truth on runs whose CF is
// 3-7 mm). Both are now inside the margin; the same data with the calibration 50 % worse on
// every run are refused, and the refusal states its margin.
TEST(NeverWorse, TheIssuesCleanRobotsAreAcceptedAndAWorseOneIsNot) {
  std::vector<AlignedRun> runs = Family("spinR", 1, 2);
  for (const AlignedRun& g : Family("G", 12, 1)) runs.push_back(g);
  const std::vector<double> nominal = {0.00319512 * 0.9, 0.00319512 * 1.1, 0.0066, 0.0080,
                                       0.0072,           0.0075,           0.0069, 0.0078,
                                       0.0070,           0.0074,           0.0073, 0.0071,
                                       0.0077,           0.007218};
  std::vector<double> calibrated = nominal;
  calibrated[0] = 0.00360461 * 0.92;
  calibrated[1] = 0.00360461 * 1.08;
  for (std::size_t i = 2; i < calibrated.size(); ++i) calibrated[i] *= 0.00737964 / 0.00728501;
  const std::vector<NeverWorseJudgement> clean = JudgeNeverWorseOnCf(runs, nominal, calibrated);
  EXPECT_EQ(Refusals(clean), 0) << NeverWorseRefusals("ceres", clean).front();
  std::vector<double> worse = nominal;
  for (double& v : worse) v *= 1.5;
  const std::vector<std::string> lines =
      NeverWorseRefusals("ceres", JudgeNeverWorseOnCf(runs, nominal, worse));
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines.front().find("more than the margin"), std::string::npos) << lines.front();
}

// The rates the rule promises, counted on the generator. Per draw: two families, spins of 1 label
// x 2 repetitions and flowers of 12 labels x 5 repetitions, run-to-run scatter sigma = 10 %.
// - No worse (shift 0): every comparison is a true null; the rule sets alpha = 5 % for all of
//   them together (Bonferroni), so at most 5 % of the draws may refuse: of 400 draws, at most
//   20 + 3 sqrt(400 x 0.05 x 0.95) = 33.
// - Truly worse by 30 % on every run (a 2 % scaled wheel raises a 1 m run's final-pose error by
//   2 cm on a CF of 7 mm: far more): refused in at least 95 % of draws (380 of 400) - the flower
//   family alone has 60 runs, so its margin is ~ t x 0.1 x sqrt(2/60) ~ 6 %.
TEST(NeverWorse, FalseRefusalAndFalseAcceptanceRates) {
  std::vector<AlignedRun> runs = Family("spin", 1, 2);
  for (const AlignedRun& g : Family("G", 12, 5)) runs.push_back(g);
  std::mt19937_64 rng(20261129);
  constexpr int kDraws = 400;
  int false_refusals = 0, refused_worse = 0;
  for (int d = 0; d < kDraws; ++d) {
    const std::vector<double> nominal = Draw(runs, 0.1, 0.0, &rng);
    false_refusals += Refusals(JudgeNeverWorseOnCf(runs, nominal, Draw(runs, 0.1, 0.0, &rng))) > 0;
    refused_worse += Refusals(JudgeNeverWorseOnCf(runs, nominal, Draw(runs, 0.1, 0.3, &rng))) > 0;
  }
  EXPECT_LE(false_refusals, 33);
  EXPECT_GE(refused_worse, 380);
}

// Drift carries its windows as weights: a run without windows (shorter than the length) neither
// counts in the mean nor in the scatter.
TEST(NeverWorse, RunsWithoutWindowsWeighNothing) {
  const std::vector<std::string> labels = {"a", "a", "a"};
  const NeverWorseJudgement j = JudgeMeasure("drift 5 m [%]", "runs", labels, {2.0, 2.0, 0.0},
                                             {1.0, 1.0, 0.0}, {1.0, 1.0, 100.0}, {}, 1);
  EXPECT_DOUBLE_EQ(j.nominal, 1.0);
  EXPECT_DOUBLE_EQ(j.calibrated, 1.0);
  EXPECT_EQ(j.spread.dof, 2);  // one per calibration: runs 1 and 2
}

}  // namespace
}  // namespace fitcal
