// The wheel order / sign check and the units check that run before a fit
// (diagnosis/wheel_order_check.h), on simulated runs (tools/sim) with the documented default noise
// and the simulator's true robot (Palacin Table 5) differing from the nominal (Eq. 15), as in a
// real calibration.

#include "diagnosis/wheel_order_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tools/sim/omni3_simulator.h"

namespace fitcal {
namespace {

std::vector<RunLog> SimulateLogs(std::uint64_t seed, int repetitions) {
  sim::Omni3SimulationOptions options;
  options.seed = seed;
  options.repetitions = repetitions;
  std::vector<RunLog> logs;
  for (auto& run : sim::SimulateOmni3(options)) logs.push_back(std::move(run.log));
  return logs;
}

// Rewires the recorded columns so that `fix` is what repairs them:
// recorded[fix.column[i]] = fix.sign[i] * true rate of wheel i.
std::vector<AlignedRun> Miswire(const std::vector<AlignedRun>& runs, const WheelMapping& fix) {
  std::vector<AlignedRun> out = runs;
  for (AlignedRun& run : out) {
    for (auto&& s : run.samples) {
      const double w[3] = {s.value[0], s.value[1], s.value[2]};
      for (int i = 0; i < 3; ++i) s.value[fix.column[i]] = fix.sign[i] * w[i];
    }
  }
  return out;
}

TEST(WheelOrderCheck, FQuantileMatchesTables) {
  // Golden values: F tables (e.g. NIST/SEMATECH e-Handbook 1.3.6.7.3).
  EXPECT_NEAR(FDistributionQuantile(0.95, 10, 10), 2.978, 2e-3);
  EXPECT_NEAR(FDistributionQuantile(0.99, 5, 5), 10.967, 2e-2);
  EXPECT_NEAR(FDistributionQuantile(0.95, 1, 30), 4.171, 2e-3);
}

TEST(WheelOrderCheck, FortyEightDistinctMappingsIdentityFirst) {
  const std::vector<WheelMapping> all = AllWheelMappings();
  ASSERT_EQ(all.size(), 48u);
  EXPECT_TRUE(all[0].IsIdentity());
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_FALSE(all[i].IsIdentity()) << i;
  WheelMapping swap;
  swap.column = {1, 0, 2};
  EXPECT_EQ(DescribeWheelMapping(swap), "columns w_a and w_b swapped");
  WheelMapping flip;
  flip.sign = {1, 1, -1};
  EXPECT_EQ(DescribeWheelMapping(flip), "wheel c = -w_c (sign flipped)");
}

TEST(WheelOrderCheck, CorrectlyWiredRunsPassForSeveralSeeds) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const std::vector<AlignedRun> runs = AlignRuns(SimulateLogs(seed, 2));
    const WheelOrderReport report = CheckWheelOrder(runs, sim::PalacinApr02Robot());
    EXPECT_FALSE(report.likely_miswired) << "seed " << seed << ": " << report.message;
  }
}

TEST(WheelOrderCheck, EveryKindOfMiswiringIsFoundAndNamed) {
  const std::vector<AlignedRun> runs = AlignRuns(SimulateLogs(4, 1));
  // A transposition, a sign flip, a cyclic shift, and a transposition with a flip.
  std::vector<WheelMapping> cases(4);
  cases[0].column = {1, 0, 2};
  cases[1].sign = {1, 1, -1};
  cases[2].column = {1, 2, 0};
  cases[3].column = {0, 2, 1};
  cases[3].sign = {-1, 1, 1};
  for (const WheelMapping& fix : cases) {
    SCOPED_TRACE(DescribeWheelMapping(fix));
    const WheelOrderReport report = CheckWheelOrder(Miswire(runs, fix), sim::PalacinApr02Robot());
    ASSERT_TRUE(report.likely_miswired);
    EXPECT_EQ(report.best.column, fix.column);
    EXPECT_EQ(report.best.sign, fix.sign);
    EXPECT_TRUE(report.fitted);
    EXPECT_GT(report.recorded_ssr / report.best_ssr, report.threshold);
    EXPECT_NE(report.message.find(DescribeWheelMapping(fix)), std::string::npos) << report.message;
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
  sim::Omni3SimulationOptions options;
  options.seed = seed;
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
  for (auto& run : sim::SimulateOmni3(options)) out.logs.push_back(std::move(run.log));
  out.runs = AlignRuns(out.logs);
  for (const RunLog& log : out.logs) out.tracks.push_back(&log.ground_truth);
  return out;
}

TEST(WheelOrderCheck, SegmentsFindASwapThatClosedCirclesHideFromFinalPoses) {
  const CircleRuns circles = SimulateCircles(6);
  WheelMapping swap;
  swap.column = {1, 0, 2};
  const std::vector<AlignedRun> miswired = Miswire(circles.runs, swap);
  // The yaw rate is symmetric in the wheels, so the swapped odometry closes its own circle too:
  // the final poses barely tell the two orders apart.
  const WheelOrderReport final_pose = CheckWheelOrder(miswired, sim::PalacinApr02Robot());
  EXPECT_FALSE(final_pose.likely_miswired) << final_pose.message;
  const WheelOrderReport segments =
      CheckWheelOrderOnSegments(miswired, circles.tracks, sim::PalacinApr02Robot());
  ASSERT_TRUE(segments.likely_miswired);
  EXPECT_EQ(segments.best.column, swap.column);
  EXPECT_EQ(segments.best.sign, swap.sign);
  EXPECT_NE(segments.message.find("columns w_a and w_b swapped"), std::string::npos)
      << segments.message;
  std::printf("final-pose ratio %.3g (threshold %.3g); segment ratio %.3g (threshold %.3g)\n",
              final_pose.recorded_ssr / final_pose.best_ssr, final_pose.threshold,
              segments.recorded_ssr / segments.best_ssr, segments.threshold);
}

TEST(WheelOrderCheck, SegmentsFindEveryKindOfMiswiringAndPassCorrectWiring) {
  std::vector<WheelMapping> cases(3);
  cases[0].sign = {1, -1, 1};
  cases[1].column = {2, 0, 1};
  cases[2].column = {2, 1, 0};
  cases[2].sign = {1, 1, -1};
  for (std::uint64_t seed : {7u, 8u, 9u}) {
    const CircleRuns circles = SimulateCircles(seed);
    const WheelOrderReport ok =
        CheckWheelOrderOnSegments(circles.runs, circles.tracks, sim::PalacinApr02Robot());
    EXPECT_FALSE(ok.likely_miswired) << "seed " << seed << ": " << ok.message;
    const WheelMapping& fix = cases[seed - 7];
    SCOPED_TRACE(DescribeWheelMapping(fix));
    const WheelOrderReport bad = CheckWheelOrderOnSegments(
        Miswire(circles.runs, fix), circles.tracks, sim::PalacinApr02Robot());
    ASSERT_TRUE(bad.likely_miswired);
    EXPECT_EQ(bad.best.column, fix.column);
    EXPECT_EQ(bad.best.sign, fix.sign);
  }
  // The flower too (open paths; every run gives one or two windows).
  const std::vector<RunLog> logs = SimulateLogs(10, 1);
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : logs) tracks.push_back(&log.ground_truth);
  const WheelOrderReport flower =
      CheckWheelOrderOnSegments(AlignRuns(logs), tracks, sim::PalacinApr02Robot());
  EXPECT_FALSE(flower.likely_miswired) << flower.message;
}

TEST(WheelOrderCheck, RatesInDegreesPerSecondAreNamed) {
  std::vector<RunLog> logs = SimulateLogs(5, 1);
  const RateUnitsReport ok = CheckRateUnits(logs, sim::PalacinApr02Robot());
  EXPECT_FALSE(ok.suspicious) << ok.message;
  // The true radii are within 1 % of the nominal: the scale is 1 to within the path-length
  // inflation of the ground-truth noise (a few %).
  EXPECT_NEAR(ok.scale, 1.0, 0.1);
  for (RunLog& log : logs) {
    for (auto&& s : log.encoders.samples) {
      for (int i = 0; i < 3; ++i) s.value[i] *= 180.0 / M_PI;
    }
  }
  const RateUnitsReport deg = CheckRateUnits(logs, sim::PalacinApr02Robot());
  EXPECT_TRUE(deg.suspicious);
  EXPECT_EQ(deg.likely_unit, "deg/s");
  EXPECT_NE(deg.message.find("likely units: deg/s"), std::string::npos) << deg.message;
}

TEST(WheelOrderCheck, RejectsInvalidOptions) {
  WheelOrderOptions options;
  options.false_alarm_probability = 0.0;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THROW(CheckWheelOrder({}, sim::PalacinApr02Robot()), std::invalid_argument);
}

}  // namespace
}  // namespace fitcal
