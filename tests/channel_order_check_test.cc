// The one channel-order check (diagnosis/channel_order_check.h) on omni3 through the model seam:
// what tests/wheel_order_check_test.cc checks of the omni3-only check, ported - simulated runs
// (sim/) with the documented default noise and the simulator's true robot (Palacin Table 5)
// differing from the nominal (Eq. 15), as in a real calibration.

#include "diagnosis/channel_order_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "models/omni3/omni3_robot_model.h"
#include "tests/test_files.h"
#include "tests/flower_scenario.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace channel_order_check_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

std::vector<RunLog> SimulateLogs(std::uint64_t seed, int repetitions) {
  sim::FlowerSimulation options = sim::PalacinFlower();
  options.options.seed = seed;
  options.repetitions = repetitions;
  std::vector<RunLog> logs = sim::SimulateFlowerLogs(options);
  return logs;
}

const RobotModelInterface& Model() {
  static const auto model = Omni3ModelOf(sim::PalacinApr02Robot());
  return *model;
}

ChannelMapping Mapping(std::vector<int> column, std::vector<int> sign = {1, 1, 1}) {
  ChannelMapping m;
  m.column = std::move(column);
  m.sign = std::move(sign);
  return m;
}

// Rewires the recorded columns so that `fix` is what repairs them:
// recorded[fix.column[i]] = fix.sign[i] * true rate of wheel i.
std::vector<AlignedRun> Miswire(const std::vector<AlignedRun>& runs, const ChannelMapping& fix) {
  std::vector<AlignedRun> out = runs;
  for (AlignedRun& run : out) {
    for (auto&& s : run.samples) {
      const double w[3] = {s.value[0], s.value[1], s.value[2]};
      for (int i = 0; i < 3; ++i) s.value[fix.column[i]] = fix.sign[i] * w[i];
    }
  }
  return out;
}

TEST(ChannelOrderCheck, FQuantileMatchesTables) {
  // Golden values: F tables (e.g. NIST/SEMATECH e-Handbook 1.3.6.7.3).
  EXPECT_NEAR(FDistributionQuantile(0.95, 10, 10), 2.978, 2e-3);
  EXPECT_NEAR(FDistributionQuantile(0.99, 5, 5), 10.967, 2e-2);
  EXPECT_NEAR(FDistributionQuantile(0.95, 1, 30), 4.171, 2e-3);
}

TEST(ChannelOrderCheck, Omni3HasFortyEightDistinctMappingsIdentityFirst) {
  const std::vector<ChannelMapping> all = Model().CandidateMiswirings();
  ASSERT_EQ(all.size(), 48u);
  EXPECT_TRUE(all[0].IsIdentity());
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_FALSE(all[i].IsIdentity()) << i;
  EXPECT_EQ(DescribeChannelMapping(Model().robot(), Mapping({1, 0, 2})),
            "columns w_a and w_b swapped");
  EXPECT_EQ(DescribeChannelMapping(Model().robot(), Mapping({0, 1, 2}, {1, 1, -1})),
            "c = -w_c (sign flipped)");
}

TEST(ChannelOrderCheck, CorrectlyWiredOmni3RunsPassForSeveralSeeds) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const std::vector<AlignedRun> runs = AlignRuns(SimulateLogs(seed, 2));
    const ChannelOrderReport report = CheckChannelOrder(runs, {}, Model());
    EXPECT_FALSE(report.likely_miswired) << "seed " << seed << ": " << report.message;
  }
}

TEST(ChannelOrderCheck, EveryKindOfOmni3MiswiringIsFoundAndNamed) {
  const std::vector<AlignedRun> runs = AlignRuns(SimulateLogs(4, 1));
  // A transposition, a sign flip, a cyclic shift, and a transposition with a flip.
  const std::vector<ChannelMapping> cases = {Mapping({1, 0, 2}), Mapping({0, 1, 2}, {1, 1, -1}),
                                             Mapping({1, 2, 0}), Mapping({0, 2, 1}, {-1, 1, 1})};
  for (const ChannelMapping& fix : cases) {
    const std::string words = DescribeChannelMapping(Model().robot(), fix);
    SCOPED_TRACE(words);
    const ChannelOrderReport report = CheckChannelOrder(Miswire(runs, fix), {}, Model());
    ASSERT_TRUE(report.likely_miswired);
    EXPECT_EQ(report.best.column, fix.column);
    EXPECT_EQ(report.best.sign, fix.sign);
    EXPECT_TRUE(report.fitted);
    EXPECT_GT(report.recorded_ssr / report.best_ssr, report.threshold);
    EXPECT_NE(report.message.find(words), std::string::npos) << report.message;
  }
}

// Full circles (closed paths) at four robot-frame directions and both spin signs: the kind of run
// a robot drives on a calibration floor and OptiOdom recorded.
struct CircleRuns {
  std::vector<RunLog> logs;
  std::vector<AlignedRun> runs;
  std::vector<const GroundTruthTrack*> tracks;
};
CircleRuns SimulateCircles(std::uint64_t seed) {
  sim::FlowerSimulation options = sim::PalacinFlower();
  options.options.seed = seed;
  options.repetitions = 1;
  options.trajectories.clear();
  const double speed = 0.3, omega = 0.5;
  for (int k = 0; k < 8; ++k) {
    sim::MotionCommand c;
    c.label = "C" + std::to_string(k + 1);
    c.speed_m_s = speed;
    c.alpha_rad = (k % 4) * M_PI / 2.0 + 0.3;
    c.omega_rad_s = k < 4 ? omega : -omega;
    c.distance_m = 2.0 * M_PI * speed / omega;  // one full circle
    options.trajectories.push_back(c);
  }
  CircleRuns out;
  for (auto& run : sim::SimulateFlower(options)) out.logs.push_back(std::move(run.log));
  out.runs = AlignRuns(out.logs);
  for (const RunLog& log : out.logs) out.tracks.push_back(&log.ground_truth);
  return out;
}

TEST(ChannelOrderCheck, WindowsFindASwapThatClosedCirclesHideFromFinalPoses) {
  const CircleRuns circles = SimulateCircles(6);
  const ChannelMapping swap = Mapping({1, 0, 2});
  const std::vector<AlignedRun> miswired = Miswire(circles.runs, swap);
  // The yaw rate is symmetric in the wheels, so the swapped odometry closes its own circle too:
  // the final poses barely tell the two orders apart.
  const ChannelOrderReport final_pose = CheckChannelOrder(miswired, {}, Model());
  EXPECT_FALSE(final_pose.likely_miswired) << final_pose.message;
  const ChannelOrderReport windows = CheckRecordedChannelOrder(miswired, circles.tracks, Model());
  ASSERT_TRUE(windows.likely_miswired);
  EXPECT_TRUE(windows.on_windows);
  EXPECT_EQ(windows.best.column, swap.column);
  EXPECT_EQ(windows.best.sign, swap.sign);
  EXPECT_NE(windows.message.find("columns w_a and w_b swapped"), std::string::npos)
      << windows.message;
}

TEST(ChannelOrderCheck, WindowsFindEveryKindOfMiswiringAndPassCorrectWiring) {
  const std::vector<ChannelMapping> cases = {Mapping({0, 1, 2}, {1, -1, 1}), Mapping({2, 0, 1}),
                                             Mapping({2, 1, 0}, {1, 1, -1})};
  for (std::uint64_t seed : {7u, 8u, 9u}) {
    const CircleRuns circles = SimulateCircles(seed);
    const ChannelOrderReport ok = CheckRecordedChannelOrder(circles.runs, circles.tracks, Model());
    EXPECT_FALSE(ok.likely_miswired) << "seed " << seed << ": " << ok.message;
    const ChannelMapping& fix = cases[seed - 7];
    SCOPED_TRACE(DescribeChannelMapping(Model().robot(), fix));
    const ChannelOrderReport bad =
        CheckRecordedChannelOrder(Miswire(circles.runs, fix), circles.tracks, Model());
    ASSERT_TRUE(bad.likely_miswired);
    EXPECT_EQ(bad.best.column, fix.column);
    EXPECT_EQ(bad.best.sign, fix.sign);
  }
  // The flower too (open paths; every run gives one or two windows).
  const std::vector<RunLog> logs = SimulateLogs(10, 1);
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : logs) tracks.push_back(&log.ground_truth);
  const ChannelOrderReport flower = CheckRecordedChannelOrder(AlignRuns(logs), tracks, Model());
  EXPECT_FALSE(flower.likely_miswired) << flower.message;
}

TEST(ChannelOrderCheck, RejectsInvalidOptionsAndNoRuns) {
  ChannelOrderOptions options;
  options.false_alarm_probability = 0.0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THROW(CheckChannelOrder({}, {}, Model()), std::invalid_argument);
  EXPECT_THROW(CheckRecordedChannelOrder({}, {nullptr}, Model()), std::invalid_argument);
}

// `diagnose` runs the same check before it fits: a flower whose encoder CSVs name columns w_a and
// w_b the wrong way round is refused with exit 4 (as `fit` refuses it), the swap named, nothing
// written.
TEST(ChannelOrderCheck, DiagnoseRefusesSwappedColumns) {
  namespace fs = std::filesystem;
  fitcal::testing::TempDir dir;
  const std::string data = dir.Path("flower");
  const std::string robot = std::string(FITCAL_SOURCE_DIR) + "/data/robots/apr02.yaml";
  const auto sim = fitcal::testing::RunFitcal(
      dir, "simulate --out " + data + " --robot " + robot + " --repetitions 2 --seed 3");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  for (const auto& entry : fs::directory_iterator(data + "/runs")) {
    const std::string path = entry.path().string();
    if (path.find("_encoders.csv") == std::string::npos) continue;
    std::string csv = fitcal::testing::ReadFileBytes(path);
    ASSERT_EQ(csv.rfind("t,w_a,w_b,w_c\n", 0), 0u) << path;
    csv.replace(0, 13, "t,w_b,w_a,w_c");
    std::ofstream(path) << csv;
  }
  const auto r =
      fitcal::testing::RunFitcal(dir, "diagnose --logs " + data + " --out " + dir.Path("diag"));
  EXPECT_EQ(r.exit_code, 4) << r.out << r.err;
  EXPECT_NE(r.err.find("columns w_a and w_b swapped"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.Path("diag")));
}

}  // namespace
}  // namespace fitcal
