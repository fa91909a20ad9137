// The two-fold judgement with nothing held out (validation/held_out_halves.h): policies over fits and scores the
// caller makes, tested here with fits that return markers and scores chosen per run, so the folds
// (every other run; odd against even time blocks), the weighting of the folds' means and the
// cases not judged are each checked on their own.
#include "validation/held_out_halves.h"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <set>

#include "tests/model_support.h"

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

// Scores the nominal (marker 1) and a fit (marker 2) by a CF per run on the fold's held-out runs
// (no track measures: the never-worse judgement then reads the CF alone).
MetricsOnFold CfPerRun(std::map<std::string, double> nominal, std::map<std::string, double> fitted) {
  return [nominal, fitted](const std::vector<double>& p, const HalvesFold& fold) {
    EverydayDrivingMetrics m;
    for (const AlignedRun& run : fold.split.validation) {
      m.per_run_cf.push_back((p[0] == 1.0 ? nominal : fitted).at(run.id));
    }
    m.runs = static_cast<int>(m.per_run_cf.size());
    return m;
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
// trains on blocks 1 and 3, fold 1 on 2 and 4; each block keeps its run's track.
TEST(HeldOutHalves, TimeBlocksOddAgainstEven) {
  GroundTruthTrack track;
  track.t_s = {0.0, 4.0};
  track.world_T_robot = {{0.0, 0.0, 0.0}, {4.0, 0.0, 0.0}};
  AlignedRun run = testing::LabelledRun("free", 1);
  run.track = std::make_shared<const GroundTruthTrack>(track);
  for (int k = 0; k < 40; ++k) run.samples.push_back(0.1, {0.0, 0.0, 0.0});
  RunSplit whole;
  whole.training = {run};
  const HalvesFold fold0 = TimeBlockFold(whole, 4, 0);
  const HalvesFold fold1 = TimeBlockFold(whole, 4, 1);
  EXPECT_EQ(Ids(fold0.split.training),
            (std::vector<std::string>{"free-1-block1", "free-1-block3"}));
  EXPECT_EQ(Ids(fold0.split.validation),
            (std::vector<std::string>{"free-1-block2", "free-1-block4"}));
  EXPECT_EQ(Ids(fold1.split.training), Ids(fold0.split.validation));
  EXPECT_EQ(Ids(fold1.split.validation), Ids(fold0.split.training));
  for (const AlignedRun& block : fold0.split.validation) EXPECT_EQ(block.track, run.track);
}

// One long run fitted on its track is judged on 2, 4 and 8 blocks, whatever --time-blocks says
// among them, and passes when the fits beat the nominal for most counts, so the verdict cannot
// flip with the count (issue 39: 4 refused, 2 and 8 wrote); another count joins the three. The
// fit is worse than the nominal on the blocks of 4 only: it passes, identically for 2, 4 and 8;
// worse on 4 and 8, it fails.
TEST(HeldOutHalves, TimeBlockVerdictDoesNotFlipWithTheCount) {
  GroundTruthTrack track;
  track.t_s = {0.0, 8.0};
  track.world_T_robot = {{0.0, 0.0, 0.0}, {8.0, 0.0, 0.0}};
  AlignedRun run = testing::LabelledRun("free", 1);
  run.track = std::make_shared<const GroundTruthTrack>(track);
  for (int k = 0; k < 80; ++k) run.samples.push_back(0.1, {0.0, 0.0, 0.0});
  RunSplit whole;
  whole.training = {run};
  std::vector<std::size_t> blocks_fitted;
  const FitOnFold fit = [&](const HalvesFold& fold) {
    blocks_fitted.push_back(fold.split.training.size() + fold.split.validation.size());
    return kCalibrated;
  };
  const auto score_worse_on = [](std::set<std::size_t> worse) -> MetricsOnFold {
    return [worse](const std::vector<double>& p, const HalvesFold& fold) {
      EverydayDrivingMetrics m;
      const std::size_t count = fold.split.training.size() + fold.split.validation.size();
      m.per_run_cf.assign(fold.split.validation.size(),
                          p[0] == 1.0 ? 1.0 : (worse.count(count) > 0 ? 1.2 : 0.5));
      return m;
    };
  };
  std::vector<HalvesJudgement> j;
  for (int count : {2, 4, 8}) {
    j.push_back(JudgeOnHeldOutHalves(whole, ResidualKind::kTrack, count, kNominal, fit,
                                     score_worse_on({4})));
  }
  EXPECT_EQ(blocks_fitted, (std::vector<std::size_t>{2, 2, 4, 4, 8, 8, 2, 2, 4, 4, 8, 8, 2, 2, 4,
                                                     4, 8, 8}));
  for (const HalvesJudgement& x : j) {
    EXPECT_TRUE(x.judged);
    EXPECT_TRUE(x.by_time);
    EXPECT_EQ(x.block_counts, (std::vector<int>{2, 4, 8}));
    ASSERT_EQ(x.groups.size(), 3u);
    EXPECT_NEAR(x.calibrated_cf, (0.5 + 1.2 + 0.5) / 3.0, 1e-12);  // the counts weigh alike
    EXPECT_TRUE(x.Beats());
  }
  EXPECT_FALSE(j[0].groups[1].Beats());
  EXPECT_FALSE(JudgeOnHeldOutHalves(whole, ResidualKind::kTrack, 4, kNominal, fit,
                                    score_worse_on({4, 8}))
                   .Beats());
  EXPECT_EQ(TimeBlockCounts(3), (std::vector<int>{2, 3, 4, 8}));
}

// A fit that returns the nominal ties it on every held-out run: judged, and it does not beat it.
TEST(HeldOutHalves, AFitReturningTheNominalDoesNotBeatIt) {
  const FitOnFold nominal_fit = [](const HalvesFold&) { return kNominal; };
  const HalvesJudgement j = JudgeOnHeldOutHalves(
      Training(4), ResidualKind::kFinalPose, 4, kNominal, nominal_fit,
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
      Training(5), ResidualKind::kFinalPose, 4, kNominal, fit,
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
  const MetricsOnFold cf = [](const std::vector<double>& p, const HalvesFold& fold) {
    EverydayDrivingMetrics m;
    m.per_run_cf.assign(fold.split.validation.size(), p[0]);
    return m;
  };
  RunSplit held_out = Training(4);
  held_out.validation.push_back(testing::LabelledRun("circle", 1));
  EXPECT_FALSE(
      JudgeOnHeldOutHalves(held_out, ResidualKind::kTrack, 4, kNominal, fit, cf).judged);
  const HalvesJudgement one_final_pose =
      JudgeOnHeldOutHalves(Training(2), ResidualKind::kFinalPose, 4, kNominal, fit, cf);
  EXPECT_FALSE(one_final_pose.judged);
  EXPECT_TRUE(one_final_pose.by_time);
  const FitOnFold fails = [](const HalvesFold&) { return std::optional<std::vector<double>>(); };
  EXPECT_FALSE(
      JudgeOnHeldOutHalves(Training(4), ResidualKind::kTrack, 4, kNominal, fails, cf).judged);
}

}  // namespace
}  // namespace fitcal
