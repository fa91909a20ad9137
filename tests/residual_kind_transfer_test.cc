// The choice of residual kind by transfer (validation/residual_kind_transfer.h): a policy over
// fits and scores the caller makes, tested here with fits that return a marker per kind and scores
// chosen per kind of run, so each rule (leave one kind out, free driving's last word, unanimity on
// closed loops, majority on free driving) is checked on its own.
#include "validation/residual_kind_transfer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <mutex>
#include <set>

#include "tests/model_support.h"
#include "validation/trajectory_family.h"

namespace fitcal {
namespace residual_kind_transfer_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

// Scores per kind of run and residual kind: {cf, drift 2 m %, ate}.
using Measures = std::array<double, 3>;
struct Table {
  std::map<std::string, Measures> track, final_pose;
};

EverydayDrivingMetrics Metrics(const Measures& m) {
  EverydayDrivingMetrics e;
  e.cf = m[0];
  e.drift.push_back({2.0, 10, m[1], 0.0});
  e.mean_ate_rmse_m = m[2];
  return e;
}

struct Harness {
  Table table;
  std::vector<std::set<std::string>> fitted_families;  // what each fit saw, in any order
  std::mutex mutex;  // the judgement calls fit_on from several threads at once
  bool fits_usable = true;

  ResidualKindJudgement Judge(const RunSplit& split) {
    const FitByKind fit_on = [this](ResidualKind kind, const std::vector<AlignedRun>& training)
        -> std::optional<std::vector<double>> {
      std::set<std::string> families;
      for (const AlignedRun& r : training) families.insert(TrajectoryFamily(r.trajectory));
      {
        const std::lock_guard<std::mutex> lock(mutex);
        fitted_families.push_back(families);
      }
      if (!fits_usable) return std::nullopt;
      return std::vector<double>{kind == ResidualKind::kTrack ? 1.0 : 2.0};
    };
    const ScoreOnRuns score = [this](const std::vector<double>& p,
                                     const std::vector<AlignedRun>& runs) {
      const std::string family = TrajectoryFamily(runs.front().trajectory);
      return Metrics(p[0] == 1.0 ? table.track.at(family) : table.final_pose.at(family));
    };
    return JudgeResidualKindsByTransfer(ResidualKind::kTrack, ResidualKind::kFinalPose, split,
                                        fit_on, score);
  }
};

RunSplit CirclesAndSquares() {
  RunSplit split;
  for (int rep = 1; rep <= 3; ++rep) {
    split.training.push_back(testing::LabelledRun("circular_1", rep));
    split.training.push_back(testing::LabelledRun("square_1", rep));
  }
  return split;
}

TEST(ResidualKindTransfer, LeavesEachKindOutAndKeepsTheTrackUnlessTheFinalPoseWinsEverything) {
  Harness h;
  h.table.track = {{"circular", {0.05, 2.0, 0.03}}, {"square", {0.06, 2.5, 0.04}}};
  // The final pose better on five of six comparisons: not enough on closed loops.
  h.table.final_pose = {{"circular", {0.04, 1.9, 0.02}}, {"square", {0.05, 2.4, 0.05}}};
  ResidualKindJudgement j = h.Judge(CirclesAndSquares());
  ASSERT_TRUE(j.judged);
  EXPECT_FALSE(j.on_free_driving);
  EXPECT_EQ(j.total, 6);
  EXPECT_EQ(j.alternative_wins, 5);
  EXPECT_EQ(j.chosen, ResidualKind::kTrack);
  ASSERT_EQ(j.comparisons.size(), 2u);
  // Each judged kind was left out of both of its fits.
  ASSERT_EQ(h.fitted_families.size(), 4u);
  // Both kinds fitted without the circles and both without the squares (the fits run at once).
  EXPECT_EQ(std::count(h.fitted_families.begin(), h.fitted_families.end(),
                       std::set<std::string>{"square"}),
            2);
  EXPECT_EQ(std::count(h.fitted_families.begin(), h.fitted_families.end(),
                       std::set<std::string>{"circular"}),
            2);

  h.table.final_pose["square"][2] = 0.03;  // now better everywhere
  j = h.Judge(CirclesAndSquares());
  EXPECT_EQ(j.alternative_wins, 6);
  EXPECT_EQ(j.chosen, ResidualKind::kFinalPose);
  const std::vector<std::string> lines = ResidualKindJudgementLines(j);
  EXPECT_FALSE(lines.empty());
  // No line padded with trailing spaces (issue 42: the rows ended in the last column's padding).
  for (const std::string& line : lines) EXPECT_NE(line.back(), ' ') << "'" << line << "'";
}

TEST(ResidualKindTransfer, HeldOutFreeDrivingHasTheLastWordByMajority) {
  Harness h;
  RunSplit split = CirclesAndSquares();
  split.validation.push_back(testing::LabelledRun("free/0201", 1));
  // Closed loops would say final pose everywhere; free driving is asked alone.
  h.table.track = {{"free", {0.05, 2.0, 0.030}}};
  h.table.final_pose = {{"free", {0.06, 1.9, 0.025}}};  // better on 2 of 3
  ResidualKindJudgement j = h.Judge(split);
  ASSERT_TRUE(j.judged);
  EXPECT_TRUE(j.on_free_driving);
  EXPECT_EQ(j.total, 3);
  EXPECT_EQ(j.chosen, ResidualKind::kFinalPose);
  ASSERT_EQ(h.fitted_families.size(), 2u);  // both fitted on every training run
  EXPECT_EQ(h.fitted_families[0], (std::set<std::string>{"circular", "square"}));

  h.table.final_pose["free"] = {0.06, 2.1, 0.025};  // better on 1 of 3
  EXPECT_EQ(h.Judge(split).chosen, ResidualKind::kTrack);
}

TEST(ResidualKindTransfer, NothingToJudgeKeepsTheProposal) {
  Harness h;
  RunSplit one_kind;
  for (int rep = 1; rep <= 4; ++rep) one_kind.training.push_back(testing::LabelledRun("circular_1", rep));
  ResidualKindJudgement j = h.Judge(one_kind);
  EXPECT_FALSE(j.judged);
  EXPECT_EQ(j.chosen, ResidualKind::kTrack);
  EXPECT_TRUE(ResidualKindJudgementLines(j).empty());

  h.fits_usable = false;  // a fit that is not usable: no judgement, the proposal stands
  j = h.Judge(CirclesAndSquares());
  EXPECT_FALSE(j.judged);
  EXPECT_EQ(j.chosen, ResidualKind::kTrack);
}

}  // namespace
}  // namespace fitcal
