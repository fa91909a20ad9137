// The noise floor from the sensors (diagnosis/sensor_noise_floor.h): the chi-square tail, the
// estimator of the two noise processes, their propagation to a run's errors against a Monte
// Carlo of the nonlinear replay, and the test on residuals drawn from the floor and above it.
#include "diagnosis/sensor_noise_floor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fit/statistics.h"

namespace fitcal {
namespace {

// Closed forms: chi2(2) has P(X > x) = exp(-x / 2); chi2(1) has erfc(sqrt(x / 2)).
TEST(ChiSquareTail, MatchesClosedForms) {
  for (double x : {0.01, 0.5, 1.0, 3.0, 10.0, 40.0}) {
    EXPECT_NEAR(stats::ChiSquareUpperTail(x, 2.0), std::exp(-0.5 * x), 1e-12 * (1.0 + 1.0 / x));
    EXPECT_NEAR(stats::ChiSquareUpperTail(x, 1.0), std::erfc(std::sqrt(0.5 * x)), 1e-12);
  }
  // Large df: the median of chi2(df) is close to df (1 - 2 / (9 df))^3 (Wilson-Hilferty).
  const double df = 1700.0;
  EXPECT_NEAR(stats::ChiSquareUpperTail(df * std::pow(1.0 - 2.0 / (9.0 * df), 3.0), df), 0.5, 1e-3);
}

// A ground-truth path: a petal of Palacin's flower (1 m out at 0.35 m/s while turning at
// 0.35 rad/s, then a spin back), sampled every dt.
std::vector<Pose2d> Petal(double dt, int samples) {
  std::vector<Pose2d> path(samples);
  for (int j = 1; j < samples; ++j) {
    const double t = j * dt;
    const double v = t < 3.0 ? 0.35 : 0.0, omega = 0.35;
    const Pose2d& p = path[j - 1];
    path[j] = {p.x + v * dt * std::cos(p.theta + 0.5 * omega * dt),
               p.y + v * dt * std::sin(p.theta + 0.5 * omega * dt), p.theta + omega * dt};
  }
  return path;
}

// One draw of the model of the header: the odometry follows the true steps, each disturbed in
// the body frame by the walk (x, y, theta), and is compared with a ground truth that carries
// white noise; the replay starts at sample 0's measured pose. Composition is nonlinear, so the
// Monte Carlo checks the linearised propagation too.
TrackErrors Draw(const std::vector<Pose2d>& truth, const SensorNoise& noise, double dt,
                 std::mt19937_64& rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  const auto gt_noise = [&](const Pose2d& p) {
    return Pose2d{p.x + std::sqrt(noise.ground_truth_var[0]) * unit(rng),
                  p.y + std::sqrt(noise.ground_truth_var[1]) * unit(rng),
                  p.theta + std::sqrt(noise.ground_truth_var[2]) * unit(rng)};
  };
  TrackErrors t;
  Pose2d odo = gt_noise(truth[0]);
  for (std::size_t j = 0; j < truth.size(); ++j) {
    if (j > 0) {
      // The true step in the body frame of the previous true pose, plus the walk.
      const Pose2d& a = truth[j - 1];
      const Pose2d& b = truth[j];
      const double c = std::cos(a.theta), s = std::sin(a.theta);
      const double bx =
          c * (b.x - a.x) + s * (b.y - a.y) + std::sqrt(noise.walk_var_per_interval[0]) * unit(rng);
      const double by = -s * (b.x - a.x) + c * (b.y - a.y) +
                        std::sqrt(noise.walk_var_per_interval[1]) * unit(rng);
      const double bt = b.theta - a.theta + std::sqrt(noise.walk_var_per_interval[2]) * unit(rng);
      const double co = std::cos(odo.theta), so = std::sin(odo.theta);
      odo = {odo.x + co * bx - so * by, odo.y + so * bx + co * by, odo.theta + bt};
    }
    const Pose2d measured = j == 0 ? odo : gt_noise(truth[j]);
    t.t_s.push_back(dt * static_cast<double>(j));
    t.ground_truth.push_back(measured);
    t.error.push_back({odo.x - measured.x, odo.y - measured.y, odo.theta - measured.theta});
  }
  t.final_error = t.error.back();
  return t;
}

SensorNoise Noise() {
  SensorNoise n;
  n.available = true;
  n.ground_truth_var = {std::pow(2e-3, 2), std::pow(2e-3, 2), std::pow(0.2 * M_PI / 180, 2)};
  n.walk_var_per_interval = {std::pow(1e-3, 2), std::pow(0.5e-3, 2), std::pow(0.001, 2)};
  return n;
}

// `runs` draws of the petal sampled every dt; the walk's grid interval holds `grid_steps` dt
// steps, so the estimate of q^2 is grid_steps times the per-step walk drawn, and s^2 is the
// drawn white noise. Tolerances about 5 standard errors (below): 7 % on s^2, and 20 % of the
// larger of q^2 and s^2 on q^2.
void ExpectEstimatorRecovers(const SensorNoise& truth, double dt, int runs, int grid_steps,
                             std::uint64_t seed) {
  const int samples = static_cast<int>(std::lround(6.0 / dt)) + 1;
  const std::vector<Pose2d> path = Petal(dt, samples);
  std::mt19937_64 rng(seed);
  std::vector<TrackErrors> tracks;
  for (int r = 0; r < runs; ++r) tracks.push_back(Draw(path, truth, dt, rng));
  const SensorNoise est = EstimateSensorNoise(tracks);
  ASSERT_TRUE(est.available);
  EXPECT_EQ(est.num_intervals, runs * ((samples - 1) / grid_steps));
  for (int c = 0; c < 3; ++c) {
    SCOPED_TRACE(c);
    const double q2 = grid_steps * truth.walk_var_per_interval[c];
    EXPECT_NEAR(est.ground_truth_var[c], truth.ground_truth_var[c],
                0.07 * truth.ground_truth_var[c]);
    EXPECT_NEAR(est.walk_var_per_interval[c], q2, 0.2 * std::max(q2, truth.ground_truth_var[c]));
  }
}

// 2000 runs x 24 intervals: the pooled lag-0 and lag-1 autocovariances have standard errors of
// about sqrt(10 / N) s^2 = 1.4 % of s^2 (N = 48000 intervals, gamma_0 = q^2 + 2 s^2 <= 3 s^2) and
// sqrt(58 / N) = 3.5 % for q^2 = gamma_0 - 2 s^2 when q^2 ~ s^2. Swapping the two processes, or
// reading gamma_1 with the wrong sign, misses by 100 %.
TEST(SensorNoiseFloor, EstimatorRecoversBothProcesses) {
  ExpectEstimatorRecovers(Noise(), 0.25, 2000, 1, 11);
}

// Ground truth every 50 ms: the walk is estimated on samples 0.2 s apart, so four 50 ms steps of
// the walk make one of its intervals (q^2 read 4 times larger) and the white noise is unchanged.
// 1500 runs x 30 grid intervals: standard errors as above on N = 45000 (1.5 % and 3.6 %), the
// same tolerances.
TEST(SensorNoiseFloor, EstimatorWorksOnIntervalsOfAtLeastTwoTenthsOfASecond) {
  SensorNoise per_step = Noise();
  for (double& q : per_step.walk_var_per_interval) q /= 4.0;
  ExpectEstimatorRecovers(per_step, 0.05, 1500, 4, 14);
}

// One Monte Carlo case: ground truth every dt, the walk per dt step, `noise` as the propagation
// reads it (the walk per interval of its 0.2 s grid).
void ExpectPropagationMatchesMonteCarlo(double dt, const SensorNoise& drawn,
                                        const SensorNoise& noise, std::uint64_t seed) {
  const std::vector<Pose2d> path = Petal(dt, static_cast<int>(std::lround(6.0 / dt)) + 1);
  const std::vector<double> times = {1.1, 2.6, 4.3, 6.0};
  const double theta0 = 0.7;  // the start frame: any turn
  std::mt19937_64 rng(seed);
  constexpr int kDraws = 4000;
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(12, 12);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(12);
  std::vector<Eigen::VectorXd> samples;
  TrackErrors shape;
  for (int d = 0; d < kDraws; ++d) {
    const TrackErrors t = Draw(path, drawn, dt, rng);
    if (d == 0) shape = t;
    Eigen::VectorXd v(12);
    for (int c = 0; c < 4; ++c) {
      const double u = times[c] / dt;
      const std::size_t lo =
          std::min<std::size_t>(static_cast<std::size_t>(u + 1e-9), t.error.size() - 1);
      const std::size_t hi = std::min(lo + 1, t.error.size() - 1);
      const double w = std::max(0.0, u - static_cast<double>(lo));
      const Pose2d e{(1 - w) * t.error[lo].x + w * t.error[hi].x,
                     (1 - w) * t.error[lo].y + w * t.error[hi].y,
                     (1 - w) * t.error[lo].theta + w * t.error[hi].theta};
      v[3 * c] = std::cos(theta0) * e.x + std::sin(theta0) * e.y;
      v[3 * c + 1] = -std::sin(theta0) * e.x + std::cos(theta0) * e.y;
      v[3 * c + 2] = e.theta;
    }
    samples.push_back(v);
    mean += v / kDraws;
  }
  for (const Eigen::VectorXd& v : samples) sum += (v - mean) * (v - mean).transpose();
  const Eigen::MatrixXd empirical = sum / (kDraws - 1);
  // The propagation reads the path from the track (a noisy draw's ground truth: within 2 mm of
  // the true path, far below the lever arms of decimetres).
  const Eigen::MatrixXd predicted = PropagateSensorNoise(noise, shape, times, theta0);
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 12; ++j) {
      const double scale = std::sqrt(empirical(i, i) * empirical(j, j));
      EXPECT_NEAR(predicted(i, j), empirical(i, j), 0.1 * scale) << i << ", " << j;
    }
  }
}

// The propagated covariance of the errors at four times (between samples, and the end) against
// the empirical covariance of 4000 draws: each entry within 0.1 sqrt(C_ii C_jj) (the empirical
// entries' standard error is about sqrt(2 / 4000) = 2.2 % of that scale; 0.1 is 4.5 of them). A
// lever arm with the wrong sign, a missing start-pose term or a frame turned the wrong way moves
// the position entries by tens of percent. With ground truth every 0.25 s the grid is every
// sample; every 50 ms it is every fourth, and times inside a grid interval take its walk in
// proportion to time.
TEST(SensorNoiseFloor, PropagationMatchesAMonteCarloOfTheReplay) {
  ExpectPropagationMatchesMonteCarlo(0.25, Noise(), Noise(), 12);
  SensorNoise per_step = Noise();
  for (double& q : per_step.walk_var_per_interval) q /= 4.0;
  ExpectPropagationMatchesMonteCarlo(0.05, per_step, Noise(), 15);
}

// Residuals drawn from the floor read about 1 times it and pass; the same residuals 1.5 times
// larger fail; runs that each carry an extra error of their own, as large as the noise, read
// twice the floor in the repetition check (the runs differ by more than the sensors' noise).
TEST(SensorNoiseFloor, TestReadsTheResidualInUnitsOfTheFloor) {
  std::mt19937_64 rng(13);
  std::normal_distribution<double> unit(0.0, 1.0);
  Eigen::MatrixXd sigma(3, 3);
  sigma << 4e-6, 1e-6, 0, 1e-6, 3e-6, 2e-5, 0, 2e-5, 4e-4;
  const Eigen::MatrixXd l = sigma.llt().matrixL();
  const auto draw = [&](double scale) {
    Eigen::VectorXd z(3);
    for (int c = 0; c < 3; ++c) z[c] = unit(rng);
    return Eigen::VectorXd(scale * (l * z));
  };
  std::vector<Eigen::VectorXd> e, e_big;
  std::vector<Eigen::MatrixXd> jacobian, covariance;
  std::vector<std::string> group;
  for (int i = 0; i < 400; ++i) {
    e.push_back(draw(1.0));
    e_big.push_back(1.5 * e.back());
    jacobian.push_back(Eigen::MatrixXd::Identity(3, 1));  // one fitted offset in x
    covariance.push_back(sigma);
    group.push_back("T" + std::to_string(i / 4));
  }
  const SensorFloorTest clean = TestAgainstSensorFloor(e, jacobian, covariance, group);
  ASSERT_TRUE(clean.available);
  EXPECT_EQ(clean.df, 400 * 3 - 1);
  // chi2(1199) / 1199 has a standard deviation of sqrt(2 / 1199) = 0.041.
  EXPECT_NEAR(clean.ratio, 1.0, 4 * 0.041);
  EXPECT_GT(clean.p_value, 1e-3);
  ASSERT_TRUE(clean.has_repetition_check);
  EXPECT_EQ(clean.repetition_df, 100 * 3 * 3);
  EXPECT_GT(clean.repetition_p_above, 1e-3);
  const SensorFloorTest big = TestAgainstSensorFloor(e_big, jacobian, covariance, group);
  EXPECT_NEAR(big.ratio, 2.25 * clean.ratio, 0.05);
  EXPECT_LT(big.p_value, 1e-10);
  std::vector<Eigen::VectorXd> varying;
  for (const Eigen::VectorXd& x : e) varying.push_back(x + draw(1.0));
  const SensorFloorTest v = TestAgainstSensorFloor(varying, jacobian, covariance, group);
  // chi2(900) / 900 has a standard deviation of 0.047, times 2 here.
  EXPECT_NEAR(v.repetition_ratio, 2.0, 4 * 2 * 0.047);
  EXPECT_LT(v.repetition_p_above, 1e-10);
}

}  // namespace
}  // namespace fitcal
