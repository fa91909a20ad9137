// The segment (relative pose error) cost, the clock map and the tied fit of an omni3 on the model
// seam (models/omni3/omni3_robot_model.h, fit/model_fit.h), on simulated runs whose ground truth
// is the exact replay of known parameters (so every residual at the truth is zero to rounding and
// any tolerance below is about rounding or the search grid, stated where used).

#include "fit/segment_cost.h"

#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

#include "fit/model_fit.h"
#include "models/omni3/omni3_robot_model.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace segment_cost_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

Omni3Robot NominalRobot() {
  Omni3Robot robot;
  for (int i = 0; i < 3; ++i) {
    robot.nominal.distance_m[i] = 0.195;
    robot.nominal.radius_m[i] = 0.051;
  }
  robot.nominal.angle_rad = {DegToRad(300.0), DegToRad(60.0), DegToRad(180.0)};
  robot.bounds.distance_m = {0.17, 0.22};
  robot.bounds.radius_m = {0.0475, 0.0545};
  robot.bounds.angle_offset_rad = {DegToRad(-2.0), DegToRad(2.0)};
  return robot;
}

std::vector<double> TrueParameters() {
  omni3::Parameters p = NominalRobot().nominal;
  p.distance_m = {0.201, 0.188, 0.197};
  p.radius_m = {0.0505, 0.0518, 0.0502};
  p.angle_rad[0] += DegToRad(0.8);
  p.angle_rad[2] -= DegToRad(0.5);
  const auto a = p.ToArray();
  return {a.begin(), a.end()};
}

const RobotModelInterface& Model() {
  static const std::shared_ptr<const Omni3Model> model = Omni3ModelOf(NominalRobot());
  return *model;
}

// A run with a smooth, varying velocity (circle-like with spin and stops at both ends) and its
// exact ground truth (the replay with `truth`), 40 ms samples as OptiOdom.
RunLog SimulatedRun(const std::vector<double>& truth, int seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  const double a = u(rng), b = u(rng), c = u(rng);
  RunLog run;
  run.id = "sim" + std::to_string(seed);
  run.trajectory = "sim";
  run.repetition = seed;
  const double dt = 0.04, duration = 30.0;
  const int n = static_cast<int>(duration / dt);
  run.encoders.t_s.push_back(0.0);
  for (int k = 0; k < n; ++k) {
    const double t = (k + 0.5) * dt;
    const double ramp = std::sin(M_PI * t / duration);  // at rest at both ends
    const Twist v{0.3 * a * ramp * std::cos(0.2 * b * t), 0.3 * ramp * std::sin(0.25 * t),
                  0.6 * c * ramp * std::sin(0.1 * t + a)};
    double values[3];
    EXPECT_TRUE(Model().ChannelsForTwist(truth.data(), v, values));  // Eq. 1: w = M v
    run.encoders.samples.push_back(dt, values);
    run.encoders.t_s.push_back((k + 1) * dt);
  }
  run.ground_truth.t_s.push_back(0.0);
  run.ground_truth.world_T_robot.push_back(Pose2d{});
  Model().Replay(truth.data(), run.encoders.samples, 0, run.encoders.samples.size(), Pose2d{},
                 [&](std::size_t k, const Pose2d& pose) {
                   run.ground_truth.t_s.push_back(run.encoders.t_s[k + 1]);
                   run.ground_truth.world_T_robot.push_back(pose);
                 });
  return run;
}

struct Prepared {
  std::vector<AlignedRun> aligned;
  std::vector<std::vector<Segment>> segments;  // one window list per run
};

Prepared Prepare(const std::vector<RunLog>& runs, const SegmentOptions& options = {}) {
  Prepared p;
  p.aligned = AlignRuns(runs);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    p.segments.push_back(MakeSegments(p.aligned[i], runs[i].ground_truth, options));
  }
  return p;
}

// Mean over windows of |r| (Eq. 14 per window, weights 1) through the model's segment cost.
double SegmentCf(const std::vector<double>& p, const Prepared& prepared) {
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < prepared.aligned.size(); ++i) {
    if (prepared.segments[i].empty()) continue;
    const std::unique_ptr<ceres::CostFunction> cost(
        Model().SegmentCost(prepared.aligned[i], prepared.segments[i], ResidualWeights{}));
    std::vector<double> r(cost->num_residuals());
    const double* parameters[] = {p.data()};
    EXPECT_TRUE(cost->Evaluate(parameters, r.data(), nullptr));
    for (std::size_t k = 0; k + 2 < r.size(); k += 3) {
      sum += std::sqrt(r[k] * r[k] + r[k + 1] * r[k + 1] + r[k + 2] * r[k + 2]);
      ++count;
    }
  }
  return count > 0 ? sum / count : 0.0;
}

std::vector<double> Nominal() { return Model().robot().nominal; }

TEST(SegmentCost, ZeroAtTruthAndWindowsHaveTheSetLength) {
  const auto truth = TrueParameters();
  const Prepared p = Prepare({SimulatedRun(truth, 1), SimulatedRun(truth, 2)});
  for (const std::vector<Segment>& segments : p.segments) {
    ASSERT_GT(segments.size(), 3u);
    for (const Segment& s : segments) {
      // A window ends at the first sample boundary past 1 m; one 40 ms step at <= 0.5 m/s adds
      // at most 2 cm.
      EXPECT_GE(s.path_length_m, 1.0);
      EXPECT_LT(s.path_length_m, 1.02);
    }
  }
  EXPECT_LT(SegmentCf(truth, p), 1e-9);      // exact replay: rounding only
  EXPECT_GT(SegmentCf(Nominal(), p), 1e-3);  // 3 % radius and 1 deg angle errors over 1 m windows
}

TEST(SegmentCost, AWrongWheelSignOrOrderIsImpossibleToMiss) {
  const auto truth = TrueParameters();
  std::vector<RunLog> runs = {SimulatedRun(truth, 3)};
  const double good = SegmentCf(Nominal(), Prepare(runs));
  RunLog flipped = runs[0], swapped = runs[0];
  for (auto&& s : flipped.encoders.samples) s.value[1] = -s.value[1];
  for (auto&& s : swapped.encoders.samples) std::swap(s.value[0], s.value[2]);
  const double bad_sign = SegmentCf(Nominal(), Prepare({flipped}));
  const double bad_order = SegmentCf(Nominal(), Prepare({swapped}));
  // A sign or order error moves a 1 m window by a large fraction of its length; the nominal's
  // parameter errors by a few per cent.
  EXPECT_GT(bad_sign, 10.0 * good);
  EXPECT_GT(bad_order, 10.0 * good);
}

TEST(SegmentCost, AutodiffJacobianMatchesCentralDifferences) {
  const auto truth = TrueParameters();
  const Prepared p = Prepare({SimulatedRun(truth, 4)});
  const std::vector<double> nominal = Nominal();
  std::unique_ptr<ceres::CostFunction> cost(
      Model().SegmentCost(p.aligned[0], p.segments[0], ResidualWeights{}));
  const int m = cost->num_residuals();
  std::vector<double> r(m), jac(static_cast<std::size_t>(m) * 9);
  const double* params[] = {nominal.data()};
  double* jacobians[] = {jac.data()};
  ASSERT_TRUE(cost->Evaluate(params, r.data(), jacobians));
  for (int k = 0; k < 9; ++k) {
    const double h = 1e-7;
    auto plus = nominal, minus = nominal;
    plus[k] += h;
    minus[k] -= h;
    std::vector<double> rp(m), rm(m);
    const double* pp[] = {plus.data()};
    const double* pm[] = {minus.data()};
    cost->Evaluate(pp, rp.data(), nullptr);
    cost->Evaluate(pm, rm.data(), nullptr);
    for (int i = 0; i < m; ++i) {
      const double numeric = (rp[i] - rm[i]) / (2 * h);
      // Central differences: O(h^2) truncation + rounding ~1e-16 / h ~ 1e-9 relative to |J|.
      EXPECT_NEAR(jac[i * 9 + k], numeric, 1e-6 * (1.0 + std::abs(numeric)))
          << "residual " << i << " param " << k;
    }
  }
}

TEST(ClockMap, RecoversAGroundTruthClockOffsetAndRate) {
  const auto truth = TrueParameters();
  RunLog run = SimulatedRun(truth, 5);
  // Ground truth stamped on a clock 0.12 s late and running 1 % fast around the middle.
  ClockMap applied;
  applied.offset_s = 0.12;
  applied.rate = 0.01;
  applied.t_mid_s = 15.0;
  RunLog shifted = run;
  for (double& t : shifted.ground_truth.t_s) t = applied.Map(t);
  const AlignedRun aligned = AlignRun(run);  // encoder window (the runs start at rest)
  const ClockMap found = EstimateClockMap(Model(), truth.data(), aligned, shifted.ground_truth);
  // The grid steps are 0.01 s and 0.25 %: the exact values lie on the grid.
  EXPECT_NEAR(found.offset_s, 0.12, 0.0101);
  EXPECT_NEAR(found.rate, 0.01, 0.0026);
  // Re-stamped, the segment cost at the truth drops back to (interpolation) noise.
  const GroundTruthTrack restamped = ApplyClockMap(shifted.ground_truth, found);
  const double cf_with = SegmentCf(truth, {{aligned}, {MakeSegments(aligned, restamped, {})}});
  const double cf_without =
      SegmentCf(truth, {{aligned}, {MakeSegments(aligned, shifted.ground_truth, {})}});
  EXPECT_LT(cf_with, 0.2 * cf_without);
}

TEST(SegmentFit, RecoversKnownParametersAndTyingHoldsGroups) {
  const auto truth = TrueParameters();
  std::vector<RunLog> runs;
  for (int s = 10; s < 13; ++s) runs.push_back(SimulatedRun(truth, s));
  const Prepared p = Prepare(runs);
  ModelFitOptions options;
  options.segments = &p.segments;
  options.ceres.num_threads = 1;
  const ModelFitResult fit = FitModel(p.aligned, Model(), options);
  ASSERT_TRUE(fit.usable) << fit.message;
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(fit.parameters[k], truth[k], 1e-6) << k;  // noise-free
  EXPECT_EQ(std::count(fit.at_bound.begin(), fit.at_bound.end(), true), 0);

  // OptiOdom's reduced model (Sousa et al. 2022): common R, three radii, angles fixed.
  ParameterTying reduced_model;
  reduced_model.groups = {{"R_a", "R_b", "R_c"}};
  reduced_model.held = {"delta_a", "delta_b", "delta_c"};
  options.tying = &reduced_model;
  const ModelFitResult reduced = FitModel(p.aligned, Model(), options);
  ASSERT_TRUE(reduced.usable) << reduced.message;
  const std::vector<double> nominal = Nominal();
  EXPECT_EQ(reduced.parameters[0], reduced.parameters[1]);
  EXPECT_EQ(reduced.parameters[1], reduced.parameters[2]);
  for (int k = 6; k < 9; ++k) {
    EXPECT_EQ(reduced.parameters[k], nominal[k]);
    EXPECT_TRUE(reduced.held[k]);
  }
  // The reduced model cannot reach the truth's angle offsets: a worse, but still improved, fit.
  EXPECT_LT(SegmentCf(reduced.parameters, p), SegmentCf(nominal, p));

  ParameterTying bad;
  bad.groups = {{"R_a", "R_z"}};
  EXPECT_NE(CheckTying(Model().robot(), bad).find("'R_z'"), std::string::npos);
}

}  // namespace
}  // namespace fitcal
