// The analytic final-pose cost (models/final_pose_jacobian.h) against the autodiff one it replaces
// (ModelFinalPoseResidual, kinematic_model.h): same residuals and Jacobians, for every kind of
// analytic path (omni3, the omni model on 3 omni and 4 mecanum wheels: linear in the rates;
// diff drive with either wheel first: Jets per step), on simulated runs (constant twists) and
// real-like ones (noisy 10 ms rates with jittered intervals, rests, turns of several revolutions,
// thousands of samples across the replay's re-anchoring).
//
// Tolerance. Both paths replay the same poses (the analytic one visits the replay's own steps),
// so the residuals agree to rounding of the final subtraction. The Jacobians are the same sums in
// another order (per channel instead of per parameter, d cos = -sin dtheta instead of the
// rotations' Jet products): each of up to ~10^4 terms carries a rounding of ~1e-16 of the largest
// entry, a random walk of < 1e-13 relative. 1e-9 of the row's largest entry leaves a margin of
// 10^4 for that and catches any wrong term (a missing or mis-signed one is O(1) of it).

#include "models/final_pose_jacobian.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "models/diff_drive/diff_drive_kinematics.h"
#include "models/kinematic_model.h"
#include "models/model_registry.h"
#include "models/omni/omni_kinematics.h"
#include "models/omni3/omni3_kinematics.h"
#include "models/segment_jacobian.h"
#include "odometry/aligned_run.h"
#include "odometry/sin_cos.h"

namespace fitcal {
namespace final_pose_jacobian_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

constexpr double kRelativeTolerance = 1e-9;

const char* const kOmni3WheelYaml = R"(model: omni
name: omni_three
wheels:
  - {name: a, distance_m: 0.195, radius_m: 0.148, angle_deg: 60.0}
  - {name: b, distance_m: 0.195, radius_m: 0.148, angle_deg: 180.0}
  - {name: c, distance_m: 0.195, radius_m: 0.148, angle_deg: 300.0}
bounds: {distance_m: [0.17, 0.22], radius_m: [0.138, 0.158], angle_offset_deg: [-2.0, 2.0]}
)";

// OptiOdom's four-wheel mecanum layout (fitcal import optiodom).
const char* const kMecanumYaml = R"(model: omni
name: mecanum
wheels:
  - {name: fl, distance_m: 0.1414213562, angle_deg: 45, radius_m: 0.03, drive_angle_deg: 0, roller_angle_deg: -45}
  - {name: fr, distance_m: 0.1414213562, angle_deg: -45, radius_m: 0.03, drive_angle_deg: 180, roller_angle_deg: 45}
  - {name: rl, distance_m: 0.1414213562, angle_deg: 135, radius_m: 0.03, drive_angle_deg: 0, roller_angle_deg: 45}
  - {name: rr, distance_m: 0.1414213562, angle_deg: -135, radius_m: 0.03, drive_angle_deg: 180, roller_angle_deg: -45}
bounds: {distance_m: [0.1164213562, 0.1664213562], radius_m: [0.0255, 0.0345], angle_offset_deg: [-5, 5]}
)";

const char* const kDiffDriveLeftFirstYaml = R"(model: diff_drive
name: left_first
wheels:
  - {name: left, radius_m: 0.042}
  - {name: right, radius_m: 0.040}
wheel_separation_m: 0.200
bounds: {radius_m: [0.038, 0.046], wheel_separation_m: [0.180, 0.220]}
)";

// Runs of constant twists, 10 ms samples, from a start pose away from the origin.
std::vector<AlignedRun> SimulatedRuns(const RobotModelInterface& model) {
  const std::vector<Twist> twists = {{0.3, 0.0, 0.0}, {0.3, 0.0, 0.5}, {-0.2, 0.0, -0.9},
                                     {0.2, 0.2, 0.4}, {0.0, 0.3, 0.0}, {0.0, 0.0, 1.2}};
  std::vector<AlignedRun> runs;
  std::vector<double> values(model.robot().NumChannels());
  for (const Twist& twist : twists) {
    if (!model.ChannelsForTwist(model.robot().nominal.data(), twist, values.data())) continue;
    AlignedRun run;
    run.id = "twist" + std::to_string(runs.size());
    run.samples = EncoderSamples(model.robot().NumChannels());
    for (int k = 0; k < 700; ++k) run.samples.push_back(0.01, values.data());
    run.start = Pose2d{0.4, -1.2, 2.5};
    runs.push_back(std::move(run));
  }
  return runs;
}

// A long real-like run: the commanded twist wanders (several full turns), each wheel rate gets
// noise, intervals jitter around 10 ms, and the robot rests now and then (zero rates, as the
// aligner's merged rests).
AlignedRun RealLikeRun(const RobotModelInterface& model, unsigned seed, std::size_t n) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> jitter(0.008, 0.012);
  const int channels = model.robot().NumChannels();
  AlignedRun run;
  run.id = "real_like" + std::to_string(seed);
  run.samples = EncoderSamples(channels);
  run.start = Pose2d{-0.7, 0.3, -3.0};
  std::vector<double> values(channels);
  for (std::size_t k = 0; k < n; ++k) {
    const double phase = 2.0 * M_PI * static_cast<double>(k) / 3000.0;
    const bool holonomic =
        model.ChannelsForTwist(model.robot().nominal.data(), Twist{0.0, 0.1, 0.0}, values.data());
    const Twist twist{0.35 * std::cos(phase), holonomic ? 0.25 * std::sin(0.7 * phase) : 0.0,
                      1.1 * std::sin(1.3 * phase) + 0.4};
    model.ChannelsForTwist(model.robot().nominal.data(), twist, values.data());
    const bool resting = (k / 500) % 7 == 3;
    for (double& w : values) w = resting ? 0.0 : w * (1.0 + 0.05 * noise(rng)) + 0.2 * noise(rng);
    run.samples.push_back(jitter(rng), values.data());
  }
  return run;
}

// Row r of the analytic Jacobian j_a against autodiff's j_d (np columns), each entry within
// kRelativeTolerance of the row's largest; returns the largest relative difference. A row autodiff
// gives as zero (an empty window) must be zero on the analytic path too, and is allowed only when
// `row_may_be_empty`.
double ExpectSameJacobianRow(const std::vector<double>& j_a, const std::vector<double>& j_d, int r,
                             int np, bool row_may_be_empty) {
  double row_max = 0.0;
  for (int j = 0; j < np; ++j) row_max = std::max(row_max, std::abs(j_d[r * np + j]));
  if (row_max == 0.0) {
    EXPECT_TRUE(row_may_be_empty) << "row " << r;
    for (int j = 0; j < np; ++j) EXPECT_EQ(j_a[r * np + j], 0.0) << "row " << r;
    return 0.0;
  }
  double worst = 0.0;
  for (int j = 0; j < np; ++j) {
    const double diff = std::abs(j_a[r * np + j] - j_d[r * np + j]) / row_max;
    worst = std::max(worst, diff);
    EXPECT_LT(diff, kRelativeTolerance) << "d r" << r << " / d p" << j << ": analytic "
                                        << j_a[r * np + j] << ", autodiff " << j_d[r * np + j];
  }
  return worst;
}

// Every residual and Jacobian entry of `analytic` equals `autodiff`'s within kRelativeTolerance of
// the row's largest entry; returns the largest relative difference seen.
double ExpectSameCost(const ceres::CostFunction& analytic, const ceres::CostFunction& autodiff,
                      const std::vector<double>& p) {
  const int np = static_cast<int>(p.size());
  double r_a[3], r_d[3], r_plain[3];
  std::vector<double> j_a(3 * np), j_d(3 * np);
  const double* params[] = {p.data()};
  double* jac_a[] = {j_a.data()};
  double* jac_d[] = {j_d.data()};
  EXPECT_TRUE(analytic.Evaluate(params, r_a, jac_a));
  EXPECT_TRUE(autodiff.Evaluate(params, r_d, jac_d));
  EXPECT_TRUE(analytic.Evaluate(params, r_plain, nullptr));
  double worst = 0.0;
  for (int r = 0; r < 3; ++r) {
    // With Jacobians both paths go one sample at a time (bit for bit the same poses); without,
    // the plain replay pairs samples, equal to rounding.
    EXPECT_NEAR(r_a[r], r_d[r], kRelativeTolerance * std::max(1.0, std::abs(r_d[r])));
    EXPECT_NEAR(r_plain[r], r_d[r], kRelativeTolerance * std::max(1.0, std::abs(r_d[r])));
    worst = std::max(worst, ExpectSameJacobianRow(j_a, j_d, r, np, /*row_may_be_empty=*/false));
  }
  return worst;
}

// For a model of kinematics K: its FinalPoseCost is the analytic one, and equals autodiff on the
// simulated and real-like runs at the nominal and at parameters moved inside the bounds.
template <class K>
void CheckModel(const std::string& yaml, FinalPoseJacobianKind expected_kind) {
  const RobotModelPtr model = ReadRobotModel(YAML::Load(yaml), "test robot");
  const auto* kinematic = dynamic_cast<const KinematicModel<K>*>(model.get());
  ASSERT_NE(kinematic, nullptr) << "unexpected kinematics for " << model->robot().name;
  ASSERT_EQ(FinalPoseJacobianKindOf<K>::value, expected_kind);
  std::vector<AlignedRun> runs = SimulatedRuns(*model);
  runs.push_back(RealLikeRun(*model, 7, 4000));
  runs.push_back(RealLikeRun(*model, 8, 11500));  // an OptiOdom-length run
  const Robot& robot = model->robot();
  std::vector<double> moved = robot.nominal;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    moved[k] += (k % 2 == 0 ? 0.6 : -0.4) * (robot.bounds[k].hi - robot.bounds[k].lo) / 2.0;
  }
  const ResidualWeights sigma_weights{0.02, 0.05};
  double worst = 0.0;
  for (AlignedRun& run : runs) {
    SCOPED_TRACE(run.id);
    // The ground truth where the moved parameters end, so residuals are small and not zero.
    run.final_ground_truth = model->ReplayFinalPose(moved.data(), run.samples, run.start);
    run.final_ground_truth.x += 0.01;
    run.final_ground_truth.theta += 0.02;
    for (const ResidualWeights& weights : {ResidualWeights{}, sigma_weights}) {
      std::unique_ptr<ceres::CostFunction> analytic(model->FinalPoseCost(run, weights));
      ASSERT_NE(dynamic_cast<const FinalPoseJacobianCost<K>*>(analytic.get()), nullptr);
      std::unique_ptr<ceres::CostFunction> autodiff(
          ModelFinalPoseResidual<K>::Create(run, weights, kinematic->kinematics()));
      for (const std::vector<double>& p : {robot.nominal, moved}) {
        worst = std::max(worst, ExpectSameCost(*analytic, *autodiff, p));
      }
    }
  }
  char worst_text[32];
  std::snprintf(worst_text, sizeof(worst_text), "%.3g", worst);
  ::testing::Test::RecordProperty("worst_relative_jacobian_difference", worst_text);
}

TEST(FinalPoseJacobian, Omni3PalacinModel) {
  CheckModel<Omni3Kinematics>(FindModel("omni3")->example_yaml,
                              FinalPoseJacobianKind::kLinearInChannels);
}

TEST(FinalPoseJacobian, OmniThreeWheels) {
  CheckModel<OmniKinematics<3>>(kOmni3WheelYaml, FinalPoseJacobianKind::kLinearInChannels);
}

TEST(FinalPoseJacobian, OmniFourMecanumWheels) {
  CheckModel<OmniKinematics<4>>(kMecanumYaml, FinalPoseJacobianKind::kLinearInChannels);
}

TEST(FinalPoseJacobian, DiffDriveRightWheelFirst) {
  CheckModel<DiffDriveKinematicsT<0>>(FindModel("diff_drive")->example_yaml,
                                      FinalPoseJacobianKind::kPerSampleStep);
}

TEST(FinalPoseJacobian, DiffDriveLeftWheelFirst) {
  CheckModel<DiffDriveKinematicsT<1>>(kDiffDriveLeftFirstYaml,
                                      FinalPoseJacobianKind::kPerSampleStep);
}

// The analytic segment cost (models/segment_jacobian.h) against the autodiff ModelSegmentResidual
// it replaces in SegmentCost, on the same runs, at the nominal and at seeded random parameters
// inside the bounds: the track residual's windows [0, k] every 300 samples and at the end (the
// first at 0, an empty window), and overlapping windows that do not start at 0 (the segment
// fit's). Same tolerance as above: the poses are the plain replay's (paired samples) against the
// Jets' one at a time, so residuals agree to rounding, Jacobians to 1e-9 of the row's largest entry.
double ExpectSameSegmentCost(const ceres::CostFunction& analytic,
                             const ceres::CostFunction& autodiff, const std::vector<double>& p) {
  const int m = analytic.num_residuals();
  const int np = static_cast<int>(p.size());
  EXPECT_EQ(m, autodiff.num_residuals());
  std::vector<double> r_a(m), r_d(m), r_plain(m), j_a(m * np), j_d(m * np);
  const double* params[] = {p.data()};
  double* jac_a[] = {j_a.data()};
  double* jac_d[] = {j_d.data()};
  EXPECT_TRUE(analytic.Evaluate(params, r_a.data(), jac_a));
  EXPECT_TRUE(autodiff.Evaluate(params, r_d.data(), jac_d));
  EXPECT_TRUE(analytic.Evaluate(params, r_plain.data(), nullptr));
  double worst = 0.0;
  for (int r = 0; r < m; ++r) {
    EXPECT_EQ(r_a[r], r_plain[r]) << "row " << r;  // both the plain replay's poses
    EXPECT_NEAR(r_a[r], r_d[r], kRelativeTolerance * std::max(1.0, std::abs(r_d[r])));
    // An empty window: no derivative on either path.
    worst = std::max(worst, ExpectSameJacobianRow(j_a, j_d, r, np, /*row_may_be_empty=*/true));
  }
  return worst;
}

// Windows [0, k] every `step` samples and at the end, ground truth the replay at `p_truth` moved
// a little; and windows [k, k + 2 step] every step.
std::vector<std::vector<Segment>> SegmentSets(const RobotModelInterface& model,
                                              const AlignedRun& run,
                                              const std::vector<double>& p_truth) {
  const std::size_t n = run.samples.size();
  const std::size_t step = 300;
  std::vector<Pose2d> pose_at(n + 1);
  pose_at[0] = Pose2d{0.0, 0.0, 0.0};
  model.Replay(p_truth.data(), run.samples, 0, n, pose_at[0],
               [&pose_at](std::size_t k, const Pose2d& pose) { pose_at[k + 1] = pose; });
  const auto window = [&](std::size_t begin, std::size_t end) {
    const Pose2d& a = pose_at[begin];
    const Pose2d& b = pose_at[end];
    const double c = std::cos(a.theta), s = std::sin(a.theta);
    const double dx = b.x - a.x, dy = b.y - a.y;
    return Segment{begin, end, Pose2d{c * dx + s * dy + 0.01, -s * dx + c * dy - 0.005,
                                      b.theta - a.theta + 0.02}};
  };
  std::vector<Segment> from_start, overlapping;
  for (std::size_t k = 0; k < n; k += step) from_start.push_back(window(0, k));
  from_start.push_back(window(0, n));
  for (std::size_t k = step / 2; k + 2 * step <= n; k += step) {
    overlapping.push_back(window(k, k + 2 * step));
  }
  return {from_start, overlapping};
}

template <class K>
void CheckSegmentCost(const std::string& yaml) {
  const RobotModelPtr model = ReadRobotModel(YAML::Load(yaml), "test robot");
  const auto* kinematic = dynamic_cast<const KinematicModel<K>*>(model.get());
  ASSERT_NE(kinematic, nullptr) << "unexpected kinematics for " << model->robot().name;
  const Robot& robot = model->robot();
  std::mt19937_64 rng(47);
  std::vector<std::vector<double>> points = {robot.nominal};
  for (int t = 0; t < 3; ++t) {
    std::vector<double> p = robot.nominal;
    for (int k = 0; k < robot.NumParameters(); ++k) {
      std::uniform_real_distribution<double> inside(robot.bounds[k].lo, robot.bounds[k].hi);
      p[k] = inside(rng);
    }
    points.push_back(p);
  }
  // Its residuals are the same to the bit with and without Jacobians (ExpectSameSegmentCost),
  // which the model says, so that the track residual's memo may rely on it.
  EXPECT_TRUE(model->SegmentResidualsAlikeWithJacobians());
  std::vector<AlignedRun> runs = SimulatedRuns(*model);
  runs.push_back(RealLikeRun(*model, 9, 4000));
  runs.push_back(RealLikeRun(*model, 10, 11500));
  double worst = 0.0;
  for (const AlignedRun& run : runs) {
    SCOPED_TRACE(run.id);
    for (const std::vector<Segment>& segments : SegmentSets(*model, run, points.back())) {
      for (const ResidualWeights& weights : {ResidualWeights{}, ResidualWeights{0.02, 0.05}}) {
        std::unique_ptr<ceres::CostFunction> analytic(model->SegmentCost(run, segments, weights));
        ASSERT_NE(dynamic_cast<const SegmentJacobianCost<K>*>(analytic.get()), nullptr);
        std::unique_ptr<ceres::CostFunction> autodiff(
            ModelSegmentResidual<K>::Create(run, segments, weights, kinematic->kinematics()));
        for (const std::vector<double>& p : points) {
          worst = std::max(worst, ExpectSameSegmentCost(*analytic, *autodiff, p));
        }
      }
    }
  }
  char worst_text[32];
  std::snprintf(worst_text, sizeof(worst_text), "%.3g", worst);
  ::testing::Test::RecordProperty("worst_relative_jacobian_difference", worst_text);
}

TEST(SegmentJacobian, Omni3PalacinModel) {
  CheckSegmentCost<Omni3Kinematics>(FindModel("omni3")->example_yaml);
}

TEST(SegmentJacobian, OmniThreeWheels) { CheckSegmentCost<OmniKinematics<3>>(kOmni3WheelYaml); }

TEST(SegmentJacobian, OmniFourMecanumWheels) {
  CheckSegmentCost<OmniKinematics<4>>(kMecanumYaml);
}

TEST(SegmentJacobian, DiffDriveRightWheelFirst) {
  CheckSegmentCost<DiffDriveKinematicsT<0>>(FindModel("diff_drive")->example_yaml);
}

TEST(SegmentJacobian, DiffDriveLeftWheelFirst) {
  CheckSegmentCost<DiffDriveKinematicsT<1>>(kDiffDriveLeftFirstYaml);
}

// odometry/sin_cos.h: the steps' sine and cosine from one libm call are ceres' sin(Jet) and
// cos(Jet) bit for bit (exact equality, no tolerance: the same products in the same order), at
// zero, tiny, near +-pi, beyond 2 pi and at seeded random angles with random derivative parts; and
// the diff drive's chord ratios on Jets equal sin(a) / a and (1 - cos(a)) / a written with ceres'
// functions outside the series' range. Why bitwise: the approval tests pin fits to the last digit.
TEST(FinalPoseJacobian, SinCosIsCeresOwnBitForBit) {
  using Jet = ceres::Jet<double, 4>;
  std::mt19937_64 rng(44);
  std::uniform_real_distribution<double> angle(-10.0, 10.0), part(-3.0, 3.0);
  std::vector<double> angles = {0.0, 1e-300, 1e-8, -1e-2, 0.5, M_PI - 1e-12, -M_PI + 1e-9, 7.0};
  for (int k = 0; k < 200; ++k) angles.push_back(angle(rng));
  for (double a : angles) {
    Jet f(a, 0);
    for (int i = 0; i < 4; ++i) f.v[i] = part(rng);
    Jet s, c;
    SinCos(f, &s, &c);
    const Jet s_ceres = ceres::sin(f), c_ceres = ceres::cos(f);
    EXPECT_EQ(s.a, s_ceres.a) << a;
    EXPECT_EQ(c.a, c_ceres.a) << a;
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(s.v[i], s_ceres.v[i]) << a;
      EXPECT_EQ(c.v[i], c_ceres.v[i]) << a;
    }
    double sd = 0.0, cd = 0.0;
    SinCos(a, &sd, &cd);
    EXPECT_EQ(sd, std::sin(a));
    EXPECT_EQ(cd, std::cos(a));
    if (std::abs(a) < diff_drive::kChordSeriesMaxAngle) continue;
    Jet sin_over_a, one_minus_cos_over_a;
    diff_drive::ChordRatios(f, &sin_over_a, &one_minus_cos_over_a);
    const Jet expected_sin = ceres::sin(f) / f, expected_cos = (1.0 - ceres::cos(f)) / f;
    EXPECT_EQ(sin_over_a.a, expected_sin.a) << a;
    EXPECT_EQ(one_minus_cos_over_a.a, expected_cos.a) << a;
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(sin_over_a.v[i], expected_sin.v[i]) << a;
      EXPECT_EQ(one_minus_cos_over_a.v[i], expected_cos.v[i]) << a;
    }
  }
}

// The diff drive's chord ratios written out on Jets (diff_drive_kinematics.h) against the same
// formulas in ceres' Jet operators, both branches: exact equality of the value and every
// derivative (no tolerance: the fits pinned by the approval tests replay through them), for Jets of
// 3 (the final-pose and segment fits) and 4 (the effect fits) at zero, tiny, near the series'
// bound on both sides, and seeded random angles with random derivative parts.
template <int N>
void ExpectChordRatiosAreJetOperators() {
  using Jet = ceres::Jet<double, N>;
  std::mt19937_64 rng(45 + N);
  std::uniform_real_distribution<double> small(-0.012, 0.012), large(-10.0, 10.0), part(-3.0, 3.0);
  std::vector<double> angles = {0.0, 1e-300, -1e-8, 1e-4, std::nextafter(1e-2, 0.0), 1e-2,
                                -1e-2, 0.5, M_PI, 7.0};
  for (int k = 0; k < 300; ++k) angles.push_back(small(rng));
  for (int k = 0; k < 100; ++k) angles.push_back(large(rng));
  int series = 0;
  for (double a : angles) {
    Jet f(a, 0);
    for (int i = 0; i < N; ++i) f.v[i] = part(rng);
    Jet expected_sin, expected_cos;
    if (std::abs(a) < diff_drive::kChordSeriesMaxAngle) {
      ++series;
      const Jet a2 = f * f;
      expected_sin = 1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0)));
      expected_cos = f * (0.5 + a2 * (-1.0 / 24.0 + a2 * (1.0 / 720.0 + a2 * (-1.0 / 40320.0))));
    } else {
      expected_sin = ceres::sin(f) / f;
      expected_cos = (1.0 - ceres::cos(f)) / f;
    }
    Jet sin_over_a, one_minus_cos_over_a;
    diff_drive::ChordRatios(f, &sin_over_a, &one_minus_cos_over_a);
    EXPECT_EQ(sin_over_a.a, expected_sin.a) << a;
    EXPECT_EQ(one_minus_cos_over_a.a, expected_cos.a) << a;
    for (int i = 0; i < N; ++i) {
      EXPECT_EQ(sin_over_a.v[i], expected_sin.v[i]) << a << " d" << i;
      EXPECT_EQ(one_minus_cos_over_a.v[i], expected_cos.v[i]) << a << " d" << i;
    }
  }
  EXPECT_GT(series, 200);  // the series branch is exercised (~250 of the 300 small angles)
}

TEST(FinalPoseJacobian, ChordRatiosAreTheJetOperatorsBitForBit) {
  ExpectChordRatiosAreJetOperators<3>();
  ExpectChordRatiosAreJetOperators<4>();
}

// odometry/sin_cos.h's SinCosOfRepeatedAngle (the tricycle's steering): every result is libm's
// (and ceres' for Jets) bit for bit, whatever came before on the thread - a repeated angle, +0
// after -0 (their sines differ in sign), a NaN, another thread's angles in between.
TEST(FinalPoseJacobian, SinCosOfARepeatedAngleIsLibmsBitForBit) {
  std::mt19937_64 rng(46);
  std::uniform_real_distribution<double> angle(-4.0, 4.0), part(-3.0, 3.0);
  std::vector<double> angles = {0.0, -0.0, -0.0, 0.0, 0.0, 1.5, 1.5, std::nan(""), 1.5, -1.5};
  for (int k = 0; k < 200; ++k) {
    const double a = angle(rng);
    for (int r = k % 4; r >= 0; --r) angles.push_back(a);  // runs of 1-4 equal angles
  }
  const auto check_all = [&angles](int* mismatches) {
    for (double a : angles) {
      double s = 0.0, c = 0.0;
      SinCosOfRepeatedAngle(a, &s, &c);
      const double s_libm = std::sin(a), c_libm = std::cos(a);
      if (std::memcmp(&s, &s_libm, sizeof s) != 0 || std::memcmp(&c, &c_libm, sizeof c) != 0) {
        ++*mismatches;
      }
    }
  };
  int mismatches = 0;
  check_all(&mismatches);
  int other_thread = 0;
  std::thread other([&] { check_all(&other_thread); });
  check_all(&mismatches);  // the two threads interleave on the same sequence
  other.join();
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(other_thread, 0);

  using Jet = ceres::Jet<double, 4>;
  for (double a : angles) {
    if (std::isnan(a)) continue;
    Jet f(a, 0);
    for (int i = 0; i < 4; ++i) f.v[i] = part(rng);
    Jet s, c;
    SinCosOfRepeatedAngle(f, &s, &c);
    const Jet s_ceres = ceres::sin(f), c_ceres = ceres::cos(f);
    EXPECT_EQ(std::signbit(s.a), std::signbit(s_ceres.a)) << a;
    EXPECT_EQ(s.a, s_ceres.a) << a;
    EXPECT_EQ(c.a, c_ceres.a) << a;
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(s.v[i], s_ceres.v[i]) << a;
      EXPECT_EQ(c.v[i], c_ceres.v[i]) << a;
    }
  }
}

}  // namespace
}  // namespace fitcal
