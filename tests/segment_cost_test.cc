// The segment (relative pose error) cost, the clock map and the tied fit, on simulated runs whose
// ground truth is the exact replay of known parameters (so every residual at the truth is zero to
// rounding and any tolerance below is about rounding or the search grid, stated where used).

#include "fit/segment_cost.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace fitcal {
namespace {

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

Omni3ParameterArray TrueParameters() {
  omni3::Parameters p = NominalRobot().nominal;
  p.distance_m = {0.201, 0.188, 0.197};
  p.radius_m = {0.0505, 0.0518, 0.0502};
  p.angle_rad[0] += DegToRad(0.8);
  p.angle_rad[2] -= DegToRad(0.5);
  return p.ToArray();
}

// A run with a smooth, varying velocity (circle-like with spin and stops at both ends) and its
// exact ground truth (the replay with `truth`), 40 ms samples as OptiOdom.
RunLog SimulatedRun(const Omni3ParameterArray& truth, int seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  const double a = u(rng), b = u(rng), c = u(rng);
  RunLog run;
  run.id = "sim" + std::to_string(seed);
  run.trajectory = "sim";
  run.repetition = seed;
  const double dt = 0.04, duration = 30.0;
  const int n = static_cast<int>(duration / dt);
  const omni3::Matrix3<double> m = omni3::KinematicMatrix(truth.data());
  run.encoders.t_s.push_back(0.0);
  for (int k = 0; k < n; ++k) {
    const double t = (k + 0.5) * dt;
    const double ramp = std::sin(M_PI * t / duration);  // at rest at both ends
    const Eigen::Vector3d v(0.3 * a * ramp * std::cos(0.2 * b * t), 0.3 * ramp * std::sin(0.25 * t),
                            0.6 * c * ramp * std::sin(0.1 * t + a));
    const Eigen::Vector3d w = m * v;
    double values[3];
    for (int i = 0; i < 3; ++i) values[i] = w[i];
    run.encoders.samples.push_back(dt, values);
    run.encoders.t_s.push_back((k + 1) * dt);
  }
  run.ground_truth.t_s.push_back(0.0);
  run.ground_truth.world_T_robot.push_back(Pose2d{});
  omni3::ReplayWithMatrix(omni3::InverseKinematicMatrix(truth.data()), run.encoders.samples, 0,
                          run.encoders.samples.size(), Pose2d{},
                          [&](std::size_t k, const Pose2d& pose) {
                            run.ground_truth.t_s.push_back(run.encoders.t_s[k + 1]);
                            run.ground_truth.world_T_robot.push_back(pose);
                          });
  return run;
}

struct Prepared {
  std::vector<AlignedRun> aligned;
  std::vector<SegmentedRun> segmented;
};

Prepared Prepare(const std::vector<RunLog>& runs, const SegmentOptions& options = {}) {
  Prepared p;
  p.aligned = AlignRuns(runs);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    p.segmented.push_back(
        {&p.aligned[i], MakeSegments(p.aligned[i], runs[i].ground_truth, options)});
  }
  return p;
}

TEST(SegmentCost, ZeroAtTruthAndWindowsHaveTheSetLength) {
  const auto truth = TrueParameters();
  const Prepared p = Prepare({SimulatedRun(truth, 1), SimulatedRun(truth, 2)});
  for (const SegmentedRun& run : p.segmented) {
    ASSERT_GT(run.segments.size(), 3u);
    for (const Segment& s : run.segments) {
      // A window ends at the first sample boundary past 1 m; one 40 ms step at <= 0.5 m/s adds
      // at most 2 cm.
      EXPECT_GE(s.path_length_m, 1.0);
      EXPECT_LT(s.path_length_m, 1.02);
    }
  }
  const SegmentErrors at_truth = EvaluateSegmentErrors(truth, p.segmented, 1);
  EXPECT_LT(at_truth.cf, 1e-9);  // exact replay: rounding only
  const SegmentErrors at_nominal =
      EvaluateSegmentErrors(NominalRobot().nominal.ToArray(), p.segmented, 1);
  EXPECT_GT(at_nominal.cf, 1e-3);  // 3 % radius and 1 deg angle errors over 1 m windows
}

TEST(SegmentCost, AWrongWheelSignOrOrderIsImpossibleToMiss) {
  const auto truth = TrueParameters();
  std::vector<RunLog> runs = {SimulatedRun(truth, 3)};
  const double good =
      EvaluateSegmentErrors(NominalRobot().nominal.ToArray(), Prepare(runs).segmented, 1).cf;
  RunLog flipped = runs[0], swapped = runs[0];
  for (auto&& s : flipped.encoders.samples) s.value[1] = -s.value[1];
  for (auto&& s : swapped.encoders.samples) std::swap(s.value[0], s.value[2]);
  const double bad_sign =
      EvaluateSegmentErrors(NominalRobot().nominal.ToArray(), Prepare({flipped}).segmented, 1).cf;
  const double bad_order =
      EvaluateSegmentErrors(NominalRobot().nominal.ToArray(), Prepare({swapped}).segmented, 1).cf;
  // A sign or order error moves a 1 m window by a large fraction of its length; the nominal's
  // parameter errors by a few per cent.
  EXPECT_GT(bad_sign, 10.0 * good);
  EXPECT_GT(bad_order, 10.0 * good);
}

TEST(SegmentCost, AutodiffJacobianMatchesCentralDifferences) {
  const auto truth = TrueParameters();
  const Prepared p = Prepare({SimulatedRun(truth, 4)});
  const auto nominal = NominalRobot().nominal.ToArray();
  std::unique_ptr<ceres::CostFunction> cost(
      Omni3SegmentResidual::Create(p.segmented[0], ResidualWeights{}));
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
  const ClockMap found = EstimateClockMap(aligned, shifted.ground_truth, TrueParameters());
  // The grid steps are 0.01 s and 0.25 %: the exact values lie on the grid.
  EXPECT_NEAR(found.offset_s, 0.12, 0.0101);
  EXPECT_NEAR(found.rate, 0.01, 0.0026);
  // Re-stamped, the segment cost at the truth drops back to (interpolation) noise.
  const GroundTruthTrack restamped = ApplyClockMap(shifted.ground_truth, found);
  SegmentedRun with_map{&aligned, MakeSegments(aligned, restamped, {})};
  SegmentedRun without{&aligned, MakeSegments(aligned, shifted.ground_truth, {})};
  const double cf_with = EvaluateSegmentErrors(truth, {with_map}, 1).cf;
  const double cf_without = EvaluateSegmentErrors(truth, {without}, 1).cf;
  EXPECT_LT(cf_with, 0.2 * cf_without);
}

TEST(SegmentFit, RecoversKnownParametersAndTyingHoldsGroups) {
  const auto truth = TrueParameters();
  std::vector<RunLog> runs;
  for (int s = 10; s < 13; ++s) runs.push_back(SimulatedRun(truth, s));
  const Prepared p = Prepare(runs);
  FitOptions options;
  options.cost = CostKind::kSegment;
  options.num_threads = 1;
  const FitResult fit = FitOmni3(p.aligned, p.segmented, NominalRobot(), options);
  ASSERT_TRUE(fit.usable) << fit.message;
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(fit.parameters[k], truth[k], 1e-6) << k;  // noise-free
  EXPECT_EQ(fit.NumAtBound(), 0);

  options.tying = ParameterTying::CommonDistanceThreeRadii();
  const FitResult reduced = FitOmni3(p.aligned, p.segmented, NominalRobot(), options);
  ASSERT_TRUE(reduced.usable) << reduced.message;
  const auto nominal = NominalRobot().nominal.ToArray();
  EXPECT_EQ(reduced.parameters[0], reduced.parameters[1]);
  EXPECT_EQ(reduced.parameters[1], reduced.parameters[2]);
  for (int k = 6; k < 9; ++k) EXPECT_EQ(reduced.parameters[k], nominal[k]);
  // The reduced model cannot reach the truth's angle offsets: a worse, but still improved, fit.
  EXPECT_LT(EvaluateSegmentErrors(reduced.parameters, p.segmented, 1).cf,
            EvaluateSegmentErrors(nominal, p.segmented, 1).cf);

  std::string error;
  FitOptions bad;
  bad.tying.group = {0, 0, 0, 2, 2, 2, -1, -1, -1};  // free parameter 1 unused
  EXPECT_FALSE(bad.IsValid(&error));
}

}  // namespace
}  // namespace fitcal
