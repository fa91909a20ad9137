// The two-fold judgement with nothing held out (validation/held_out_halves.h) and the per-family
// comparison with the nominal (validation/held_out_families.h): policies over fits and scores the
// caller makes, tested here with fits that return markers and scores chosen per run, so the folds
// (every other run; odd against even time blocks), the weighting of the folds' means and the
// cases not judged are each checked on their own.
#include "validation/held_out_halves.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "tests/model_support.h"
#include "validation/held_out_families.h"

namespace fitcal {
namespace {

RunSplit Training(int num_runs) {
  RunSplit split;
  for (int i = 1; i <= num_runs; ++i) split.training.push_back(testing::LabelledRun("free", i));
  return split;
}

std::vector<std::string> Ids(const std::vector<AlignedRun>& runs) {
  std::vector<std::string> ids;
  for (const AlignedRun& run : runs) ids.push_back(run.id);
  return ids;
}

const std::vector<double> kNominal = {1.0};
const std::vector<double> kCalibrated = {2.0};

// Scores the nominal (marker 1) and a fit (marker 2) by a CF per run, mean over the runs given.
CfOnRuns CfPerRun(std::map<std::string, double> nominal, std::map<std::string, double> fitted) {
  return [nominal, fitted](const std::vector<double>& p, const std::vector<AlignedRun>& runs) {
    double sum = 0.0;
    for (const AlignedRun& run : runs) sum += (p[0] == 1.0 ? nominal : fitted).at(run.id);
    return sum / static_cast<double>(runs.size());
  };
}

// Four runs: fold 0 trains on the 1st and 3rd and is judged on the 2nd and 4th, fold 1 back.
TEST(HeldOutHalves, FoldsOfFourRunsAlternate) {
  const RunSplit whole = Training(4);
  const RunSplit fold0 = RunsFold(whole, 0), fold1 = RunsFold(whole, 1);
  EXPECT_EQ(Ids(fold0.training), (std::vector<std::string>{"free-1", "free-3"}));
  EXPECT_EQ(Ids(fold0.validation), (std::vector<std::string>{"free-2", "free-4"}));
  EXPECT_EQ(Ids(fold1.training), Ids(fold0.validation));
  EXPECT_EQ(Ids(fold1.validation), Ids(fold0.training));
}

// A straight run of 4 m over 4 s (40 encoder intervals of 0.1 s) cut into 4 blocks of 1 m: fold 0
// trains on blocks 1 and 3, fold 1 on 2 and 4; each block's track is found under its own id.
TEST(HeldOutHalves, TimeBlocksOddAgainstEven) {
  RunLog log;
  log.id = "free-1";
  log.trajectory = "free";
  log.repetition = 1;
  log.ground_truth.t_s = {0.0, 4.0};
  log.ground_truth.world_T_robot = {{0.0, 0.0, 0.0}, {4.0, 0.0, 0.0}};
  AlignedRun run = testing::LabelledRun("free", 1);
  for (int k = 0; k < 40; ++k) run.samples.push_back(0.1, {0.0, 0.0, 0.0});
  RunSplit whole;
  whole.training = {run};
  const HalvesFold fold0 = TimeBlockFold(whole, {log}, 4, 0);
  const HalvesFold fold1 = TimeBlockFold(whole, {log}, 4, 1);
  EXPECT_EQ(Ids(fold0.split.training),
            (std::vector<std::string>{"free-1-block1", "free-1-block3"}));
  EXPECT_EQ(Ids(fold0.split.validation),
            (std::vector<std::string>{"free-1-block2", "free-1-block4"}));
  EXPECT_EQ(Ids(fold1.split.training), Ids(fold0.split.validation));
  EXPECT_EQ(Ids(fold1.split.validation), Ids(fold0.split.training));
  std::set<std::string> log_ids;
  for (const RunLog& l : fold0.logs) log_ids.insert(l.id);
  for (const AlignedRun& block : fold0.split.validation) EXPECT_EQ(log_ids.count(block.id), 1u);
  EXPECT_EQ(log_ids.count("free-1"), 1u);  // the run's own log stays
}

// A fit that returns the nominal ties it on every held-out run: judged, and it does not beat it.
TEST(HeldOutHalves, AFitReturningTheNominalDoesNotBeatIt) {
  const FitOnFold nominal_fit = [](const HalvesFold&) { return kNominal; };
  const HalvesJudgement j = JudgeOnHeldOutHalves(
      Training(4), {}, ResidualKind::kFinalPose, 4, kNominal, nominal_fit,
      CfPerRun({{"free-1", 0.1}, {"free-2", 0.2}, {"free-3", 0.3}, {"free-4", 0.4}}, {}));
  EXPECT_TRUE(j.judged);
  EXPECT_FALSE(j.by_time);
  EXPECT_DOUBLE_EQ(j.nominal_cf, 0.25);
  EXPECT_DOUBLE_EQ(j.calibrated_cf, j.nominal_cf);
  EXPECT_FALSE(j.Beats());
}

// Five runs: fold 0 is judged on two runs, fold 1 on three; each held-out run weighs alike, so the
// CFs are the means over the five runs, not the mean of the two folds' means.
TEST(HeldOutHalves, HeldOutRunsWeighAlikeAcrossTheFolds) {
  std::vector<std::vector<std::string>> fitted_on;
  const FitOnFold fit = [&](const HalvesFold& fold) {
    fitted_on.push_back(Ids(fold.split.training));
    return kCalibrated;
  };
  const HalvesJudgement j = JudgeOnHeldOutHalves(
      Training(5), {}, ResidualKind::kFinalPose, 4, kNominal, fit,
      CfPerRun(
          {{"free-1", 1.0}, {"free-2", 2.0}, {"free-3", 3.0}, {"free-4", 4.0}, {"free-5", 5.0}},
          {{"free-1", 0.0}, {"free-2", 0.0}, {"free-3", 0.0}, {"free-4", 1.0}, {"free-5", 0.5}}));
  ASSERT_EQ(fitted_on.size(), 2u);
  EXPECT_EQ(fitted_on[0], (std::vector<std::string>{"free-1", "free-3", "free-5"}));
  EXPECT_TRUE(j.judged);
  EXPECT_DOUBLE_EQ(j.nominal_cf, 3.0);     // (1 + 2 + 3 + 4 + 5) / 5
  EXPECT_DOUBLE_EQ(j.calibrated_cf, 0.3);  // (0 + 0 + 0 + 1 + 0.5) / 5
  EXPECT_TRUE(j.Beats());
}

// Not judged: runs held out (the gate judges on them), one run fitted on its final pose, a fit
// that fails. One run fitted on its track is judged on time blocks (by_time).
TEST(HeldOutHalves, CasesNotJudged) {
  const FitOnFold fit = [](const HalvesFold&) { return kCalibrated; };
  const CfOnRuns cf = [](const std::vector<double>& p, const std::vector<AlignedRun>&) {
    return p[0];
  };
  RunSplit held_out = Training(4);
  held_out.validation.push_back(testing::LabelledRun("circle", 1));
  EXPECT_FALSE(
      JudgeOnHeldOutHalves(held_out, {}, ResidualKind::kTrack, 4, kNominal, fit, cf).judged);
  const HalvesJudgement one_final_pose =
      JudgeOnHeldOutHalves(Training(2), {}, ResidualKind::kFinalPose, 4, kNominal, fit, cf);
  EXPECT_FALSE(one_final_pose.judged);
  EXPECT_TRUE(one_final_pose.by_time);
  const FitOnFold fails = [](const HalvesFold&) { return std::optional<std::vector<double>>(); };
  EXPECT_FALSE(
      JudgeOnHeldOutHalves(Training(4), {}, ResidualKind::kTrack, 4, kNominal, fails, cf).judged);
}

// Per family of the held-out runs, sorted by family: the nominal's CF against the selected
// candidate's; none when the nominal was kept or the held-out runs are of one family.
TEST(HeldOutFamilies, ComparesTheSelectedWithTheNominalPerFamily) {
  const std::vector<CalibrationCandidate> candidates = {{"nominal", kNominal},
                                                        {"ceres", kCalibrated}};
  RunSplit split;
  split.validation = {testing::LabelledRun("square", 1), testing::LabelledRun("circular", 1), testing::LabelledRun("square", 2)};
  const EffectCandidateCf cf = [](const CalibrationCandidate& c,
                                  const std::vector<AlignedRun>& runs) {
    // The calibration is better on squares, worse on circles.
    const bool squares = runs.front().trajectory == "square";
    return c.parameters[0] == 1.0 ? 1.0 : (squares ? 0.5 : 1.5);
  };
  GateDecision gate;
  gate.selected = 1;
  const std::vector<FamilyComparison> c =
      CompareHeldOutFamiliesWithNominal(candidates, gate, split, cf);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].family, "circular");
  EXPECT_EQ(c[0].runs, 1u);
  EXPECT_TRUE(c[0].SelectedIsWorse());
  EXPECT_EQ(c[1].family, "square");
  EXPECT_EQ(c[1].runs, 2u);
  EXPECT_DOUBLE_EQ(c[1].nominal_cf, 1.0);
  EXPECT_DOUBLE_EQ(c[1].selected_cf, 0.5);
  EXPECT_FALSE(c[1].SelectedIsWorse());
  gate.selected = 0;
  EXPECT_TRUE(CompareHeldOutFamiliesWithNominal(candidates, gate, split, cf).empty());
  gate.selected = 1;
  split.validation.erase(split.validation.begin() + 1);  // squares only
  EXPECT_TRUE(CompareHeldOutFamiliesWithNominal(candidates, gate, split, cf).empty());
}

}  // namespace
}  // namespace fitcal
