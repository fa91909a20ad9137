// The replay of Palacin Eq. 4 (tests/omni3_reference_replay.h) against exact references: the closed
// form of Eq. 4 for a constant-rate log, the analytic arc it converges to, a naive step-by-step
// implementation that calls sin/cos at every sample, and Jet vs double evaluation.

#include "tests/omni3_reference_replay.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include <complex>
#include <random>

#include "tests/flower_scenario.h"

namespace fitcal::omni3 {
namespace omni3_replay_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

using ParameterArray = std::array<double, kNumParameters>;

ParameterArray Table5() { return sim::PalacinTable5Parameters().ToArray(); }

EncoderSamples ConstantLog(const Eigen::Vector3d& w, double dt, int n) {
  EncoderSamples samples(3);
  samples.resize(static_cast<std::size_t>(n));
  for (auto&& s : samples) {
    s.dt_s = dt;
    for (int i = 0; i < 3; ++i) s.value[i] = w[i];
  }
  return samples;
}

// Eq. 4 written literally: R(theta)^-1 * M^-1 * w with sin/cos at every sample.
Pose2d NaiveReplay(const ParameterArray& p, const EncoderSamples& samples, Pose2d pose) {
  const Eigen::Matrix3d m_inv = InverseKinematicMatrix(p.data());
  for (const auto& s : samples) {
    Eigen::Matrix3d r_inv;
    r_inv << std::cos(pose.theta), -std::sin(pose.theta), 0, std::sin(pose.theta),
        std::cos(pose.theta), 0, 0, 0, 1;
    const Eigen::Vector3d step =
        s.dt_s * r_inv * m_inv * Eigen::Vector3d(s.value[0], s.value[1], s.value[2]);
    pose.x += step[0];
    pose.y += step[1];
    pose.theta += step[2];
  }
  return pose;
}

TEST(Omni3Replay, ConstantRatesGiveTheClosedFormOfEq4) {
  // With constant body velocity v and per-step rotation D = omega dt, Eq. 4 sums
  // dt * e^{i(theta0 + j D)} (vx + i vy) over j = 0..n-1: a geometric series.
  const ParameterArray p = Table5();
  const Eigen::Vector3d w(-2.0, 0.5, 2.5);  // rad/s: a curved run
  const double dt = 0.01;
  const int n = 1000;  // crosses the re-anchoring interval several times
  const Pose2d start{0.3, -0.2, 2.5};
  const Pose2d replayed = ReplayFinalPose(p.data(), ConstantLog(w, dt, n), start);

  const Eigen::Vector3d v = InverseKinematicMatrix(p.data()) * w;
  const std::complex<double> i(0.0, 1.0);
  const double D = v[2] * dt;
  const std::complex<double> sum = std::exp(i * start.theta) * (1.0 - std::exp(i * (n * D))) /
                                   (1.0 - std::exp(i * D)) * std::complex<double>(v[0], v[1]) * dt;
  EXPECT_NEAR(replayed.x, start.x + sum.real(), 1e-12);
  EXPECT_NEAR(replayed.y, start.y + sum.imag(), 1e-12);
  EXPECT_NEAR(replayed.theta, start.theta + n * D, 1e-12);
}

TEST(Omni3Replay, ConstantRatesConvergeToTheAnalyticArc) {
  // The continuous motion is an arc: p(T) = p0 + (vx + i vy) e^{i theta0} (e^{i omega T} - 1) / (i
  // omega). Eq. 4 uses the heading at the start of each interval, so it lags by omega dt / 2 per
  // step: position error <= |v| T * omega dt / 2 (first order). Checked at two step sizes.
  const ParameterArray p = Table5();
  const Eigen::Vector3d w(1.0, -2.0, 3.0);
  const double T = 3.0;
  const Pose2d start{0.0, 0.0, -1.0};
  const Eigen::Vector3d v = InverseKinematicMatrix(p.data()) * w;
  const std::complex<double> i(0.0, 1.0);
  const std::complex<double> arc = std::complex<double>(v[0], v[1]) * std::exp(i * start.theta) *
                                   (std::exp(i * v[2] * T) - 1.0) / (i * v[2]);
  const double speed = std::hypot(v[0], v[1]);
  for (double dt : {0.01, 0.001}) {
    const int n = static_cast<int>(std::lround(T / dt));
    const Pose2d end = ReplayFinalPose(p.data(), ConstantLog(w, dt, n), start);
    const double bound = speed * T * std::abs(v[2]) * dt / 2.0 * 1.05;
    EXPECT_LE(std::hypot(end.x - arc.real(), end.y - arc.imag()), bound) << "dt " << dt;
    EXPECT_NEAR(end.theta, start.theta + v[2] * T, 1e-12);
  }
}

TEST(Omni3Replay, MatchesTheLiteralEq4OnRandomLogs) {
  // Random rates, irregular dt, and a few samples with a per-sample rotation above the series
  // range (exercises the library sin/cos path).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> rate(-30.0, 30.0), dt(0.002, 0.03);
  const ParameterArray p = Table5();
  for (int trial = 0; trial < 20; ++trial) {
    EncoderSamples samples(3);
    samples.resize(static_cast<std::size_t>(700 + 37 * trial));
    for (auto&& s : samples) {
      s.dt_s = dt(rng);
      for (int i = 0; i < 3; ++i) s.value[i] = rate(rng);
    }
    samples[5].dt_s = 0.5;  // large rotation in one step
    const Pose2d start{1.0, 2.0, -3.0};
    const Pose2d fast = ReplayFinalPose(p.data(), samples, start);
    const Pose2d naive = NaiveReplay(p, samples, start);
    // Both sum ~1000 steps of O(0.1 m): rounding differences stay below 1e-11 m.
    EXPECT_NEAR(fast.x, naive.x, 1e-11);
    EXPECT_NEAR(fast.y, naive.y, 1e-11);
    EXPECT_NEAR(fast.theta, naive.theta, 1e-11);
  }
}

TEST(Omni3Replay, VisitorSeesEveryIntermediatePose) {
  const ParameterArray p = Table5();
  const EncoderSamples samples = ConstantLog(Eigen::Vector3d(1, 2, 3), 0.01, 300);
  std::vector<Pose2d> poses;
  const Pose2d end =
      ReplayWithMatrix(InverseKinematicMatrix(p.data()), samples, 0, samples.size(), Pose2d{},
                       [&](std::size_t, const Pose2d& pose) { poses.push_back(pose); });
  ASSERT_EQ(poses.size(), samples.size());
  EXPECT_EQ(poses.back().x, end.x);
  EncoderSamples first_half(3);
  for (std::size_t k = 0; k < 150; ++k) first_half.push_back(samples[k]);
  const Pose2d half = ReplayFinalPose(p.data(), first_half, Pose2d{});
  EXPECT_NEAR(poses[149].x, half.x, 1e-15);
  EXPECT_NEAR(poses[149].y, half.y, 1e-15);
}

TEST(Omni3Replay, JetsAndDoublesAgreeAndDerivativesMatchFiniteDifferences) {
  using Jet = ceres::Jet<double, kNumParameters>;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> rate(-3.0, 3.0);
  EncoderSamples samples(3);
  samples.resize(400);
  for (auto&& s : samples) {
    s.dt_s = 0.01;
    for (int i = 0; i < 3; ++i) s.value[i] = rate(rng);
  }
  const ParameterArray p = Table5();
  const Pose2d start{0.5, 0.5, 0.5};
  std::array<Jet, kNumParameters> pj;
  for (int k = 0; k < kNumParameters; ++k) pj[k] = Jet(p[k], k);
  const Pose2<Jet> jet_end =
      ReplayFinalPose(pj.data(), samples, Pose2<Jet>{Jet(start.x), Jet(start.y), Jet(start.theta)});
  const Pose2d end = ReplayFinalPose(p.data(), samples, start);
  EXPECT_NEAR(jet_end.x.a, end.x, 1e-14);
  EXPECT_NEAR(jet_end.y.a, end.y, 1e-14);
  EXPECT_NEAR(jet_end.theta.a, end.theta, 1e-14);
  for (int k = 0; k < kNumParameters; ++k) {
    const double h = 1e-6;
    ParameterArray plus = p, minus = p;
    plus[k] += h;
    minus[k] -= h;
    const Pose2d a = ReplayFinalPose(plus.data(), samples, start);
    const Pose2d b = ReplayFinalPose(minus.data(), samples, start);
    // Central differences on O(1) outputs: error ~ h^2 f''' + eps / h ~ 1e-9.
    EXPECT_NEAR(jet_end.x.v[k], (a.x - b.x) / (2 * h), 1e-6) << k;
    EXPECT_NEAR(jet_end.y.v[k], (a.y - b.y) / (2 * h), 1e-6) << k;
    EXPECT_NEAR(jet_end.theta.v[k], (a.theta - b.theta) / (2 * h), 1e-6) << k;
  }
}

TEST(Omni3Replay, ZeroRatesStayPut) {
  const ParameterArray p = Table5();
  const Pose2d start{1.0, -1.0, 0.3};
  const Pose2d end =
      ReplayFinalPose(p.data(), ConstantLog(Eigen::Vector3d::Zero(), 0.01, 1000), start);
  EXPECT_EQ(end.x, start.x);
  EXPECT_EQ(end.y, start.y);
  EXPECT_EQ(end.theta, start.theta);
}

}  // namespace
}  // namespace fitcal::omni3
