#include "diagnosis/sensor_noise_floor.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>

#include "fit/statistics.h"
#include "odometry/pose2.h"
#include "odometry/text_format.h"

namespace fitcal {
namespace {

// Fewer intervals than this over all runs estimate no variance worth propagating.
constexpr int kMinIntervals = 30;
// The walk is estimated and propagated on ground-truth samples at least this far apart (less 10 %
// for jitter). Shorter intervals see errors that do not accumulate but are correlated over a few
// samples - an encoder period longer than the ground truth's, recorder jitter, a small latency -
// and read them as walk: on the real differential drive (20 Hz ground truth) the heading walk per
// second read 6.7e-5 rad^2 at 50 ms, 0.8-2.4e-5 at 0.1-0.8 s.
constexpr double kMinIntervalS = 0.2;

// The samples the walk is estimated and propagated on: the first, then each at least
// kMinIntervalS after the previous one kept.
std::vector<std::size_t> WalkGrid(const std::vector<double>& t_s) {
  std::vector<std::size_t> grid;
  if (t_s.empty()) return grid;
  grid.push_back(0);
  for (std::size_t j = 1; j < t_s.size(); ++j) {
    if (t_s[j] - t_s[grid.back()] >= 0.9 * kMinIntervalS) grid.push_back(j);
  }
  return grid;
}

using Increment = std::array<double, 3>;

// The residual's body-frame increments u_k (header): per ground-truth interval, the odometry's
// step error less what the heading error already there does to the step.
std::vector<Increment> BodyIncrements(const TrackErrors& t) {
  std::vector<Increment> u;
  const std::vector<std::size_t> grid = WalkGrid(t.t_s);
  for (std::size_t m = 1; m < grid.size(); ++m) {
    const std::size_t i = grid[m - 1], j = grid[m];
    const Pose2d& g0 = t.ground_truth[i];
    const Pose2d& g1 = t.ground_truth[j];
    const double e_theta = t.error[i].theta;
    const double px = t.error[j].x - t.error[i].x + e_theta * (g1.y - g0.y);
    const double py = t.error[j].y - t.error[i].y - e_theta * (g1.x - g0.x);
    const double c = std::cos(g0.theta), s = std::sin(g0.theta);
    u.push_back({c * px + s * py, -s * px + c * py,
                 std::remainder(t.error[j].theta - t.error[i].theta, 2.0 * M_PI)});
  }
  return u;
}

// The ground-truth samples (at most two) and weights an error at time t interpolates, as the
// lack-of-fit components do (residual_analysis.cc, ErrorAt).
struct Interpolation {
  std::size_t sample[2] = {0, 0};
  double weight[2] = {0.0, 0.0};
};
Interpolation At(const TrackErrors& t, double time) {
  Interpolation in;
  const std::size_t last = t.t_s.size() - 1;
  if (time <= t.t_s.front() || time >= t.t_s.back()) {
    in.sample[0] = time <= t.t_s.front() ? 0 : last;
    in.weight[0] = 1.0;
    return in;
  }
  const std::size_t hi =
      static_cast<std::size_t>(std::upper_bound(t.t_s.begin(), t.t_s.end(), time) - t.t_s.begin());
  const double u = (time - t.t_s[hi - 1]) / (t.t_s[hi] - t.t_s[hi - 1]);
  in.sample[0] = hi - 1;
  in.sample[1] = hi;
  in.weight[0] = 1.0 - u;
  in.weight[1] = u;
  return in;
}

// Adds var * a a^T to sigma.
void AddSource(double var, const Eigen::VectorXd& a, Eigen::MatrixXd* sigma) {
  if (var > 0.0) sigma->noalias() += var * a * a.transpose();
}

// The scatter of repeated runs around their set's mean, whitened by the set's mean floor: with m
// runs of covariance Sigma, sum_i (e_i - mean)^T Sigma^-1 (e_i - mean) is chi-square on
// dim (m - 1) degrees of freedom (each deviation has covariance (m - 1) / m Sigma, m of them).
void AddRepetitionCheck(const std::vector<Eigen::VectorXd>& e,
                        const std::vector<Eigen::MatrixXd>& covariance,
                        const std::vector<std::string>& group, SensorFloorTest* out) {
  std::map<std::string, std::vector<std::size_t>> sets;
  for (std::size_t i = 0; i < e.size(); ++i) sets[group[i]].push_back(i);
  double chi2 = 0.0, df = 0.0;
  for (const auto& [label, members] : sets) {
    if (members.size() < 2) continue;
    const double m = static_cast<double>(members.size());
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(e[members.front()].size());
    Eigen::MatrixXd floor = Eigen::MatrixXd::Zero(mean.size(), mean.size());
    for (std::size_t i : members) {
      mean += e[i] / m;
      floor += covariance[i] / m;
    }
    const Eigen::LLT<Eigen::MatrixXd> llt(floor);
    if (llt.info() != Eigen::Success) continue;
    for (std::size_t i : members) chi2 += llt.matrixL().solve(e[i] - mean).squaredNorm();
    df += static_cast<double>(mean.size()) * (m - 1.0);
  }
  if (!(df > 0.0)) return;
  out->has_repetition_check = true;
  out->repetition_df = df;
  out->repetition_ratio = chi2 / df;
  out->repetition_p_above = stats::ChiSquareUpperTail(chi2, df);
}

}  // namespace

double ExplainedByLinearisedRefit(const Eigen::MatrixXd& normal, const Eigen::VectorXd& rhs,
                                  int* identifiable) {
  *identifiable = 0;
  if (normal.rows() == 0) return 0.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(normal);
  const double largest = eig.eigenvalues().maxCoeff();
  double explained = 0.0;
  for (int k = 0; k < normal.rows(); ++k) {
    const double lambda = eig.eigenvalues()[k];
    if (!(lambda > 1e-10 * largest)) continue;  // a direction no run moves: not fitted
    ++*identifiable;
    const double projection = eig.eigenvectors().col(k).dot(rhs);
    explained += projection * projection / lambda;
  }
  return explained;
}

SensorNoise EstimateSensorNoise(const std::vector<TrackErrors>& tracks) {
  Increment lag0{}, lag1{};
  long n0 = 0, n1 = 0;
  for (const TrackErrors& t : tracks) {
    std::vector<Increment> u = BodyIncrements(t);
    if (u.size() < 3) continue;
    // Each run's own mean step error is systematic (e.g. a scale error on a steady motion).
    for (int c = 0; c < 3; ++c) {
      double mean = 0.0;
      for (const Increment& x : u) mean += x[c] / static_cast<double>(u.size());
      for (Increment& x : u) x[c] -= mean;
    }
    for (std::size_t k = 0; k < u.size(); ++k) {
      for (int c = 0; c < 3; ++c) {
        lag0[c] += u[k][c] * u[k][c];
        if (k > 0) lag1[c] += u[k][c] * u[k - 1][c];
      }
    }
    n0 += static_cast<long>(u.size());
    n1 += static_cast<long>(u.size()) - 1;
  }
  SensorNoise noise;
  noise.num_intervals = static_cast<int>(n0);
  if (n0 < kMinIntervals) return noise;
  for (int c = 0; c < 3; ++c) {
    const double gamma0 = lag0[c] / static_cast<double>(n0);
    const double gamma1 = lag1[c] / static_cast<double>(n1);
    noise.ground_truth_var[c] = std::max(0.0, -gamma1);
    noise.walk_var_per_interval[c] = std::max(0.0, gamma0 - 2.0 * noise.ground_truth_var[c]);
  }
  noise.available = true;
  return noise;
}

namespace {

// Sample j's own noise, -n_j, where a time reads sample j (the start's, j = 0, is AddStartNoise's).
void AddGroundTruthNoise(double s_xy, double s_theta, const std::vector<Interpolation>& at,
                         Eigen::MatrixXd* sigma) {
  Eigen::VectorXd a(sigma->rows());
  std::map<std::size_t, std::vector<std::pair<int, double>>> readers;  // sample -> (time, weight)
  for (int c = 0; c < static_cast<int>(at.size()); ++c) {
    for (int h = 0; h < 2; ++h) {
      if (at[c].weight[h] != 0.0) readers[at[c].sample[h]].push_back({c, at[c].weight[h]});
    }
  }
  for (int axis = 0; axis < 3; ++axis) {
    for (const auto& [j, list] : readers) {
      if (j == 0) continue;
      a.setZero();
      for (const auto& [c, w] : list) a[3 * c + axis] -= w;
      AddSource(axis == 2 ? s_theta : s_xy, a, sigma);
    }
  }
}

// The start: the replay begins at sample 0's measured pose, so n_0 moves every later error (its
// heading through the lever arm to the sample) and cancels at sample 0 itself.
void AddStartNoise(double s_xy, double s_theta, const std::vector<Pose2d>& g,
                   const std::vector<Interpolation>& at, Eigen::MatrixXd* sigma) {
  Eigen::VectorXd a(sigma->rows());
  for (int axis = 0; axis < 3; ++axis) {
    a.setZero();
    for (int c = 0; c < static_cast<int>(at.size()); ++c) {
      for (int h = 0; h < 2; ++h) {
        const std::size_t j = at[c].sample[h];
        const double w = at[c].weight[h];
        if (w == 0.0 || j == 0) continue;
        if (axis < 2) {
          a[3 * c + axis] += w;
        } else {
          a[3 * c + 0] -= w * (g[j].y - g[0].y);
          a[3 * c + 1] += w * (g[j].x - g[0].x);
          a[3 * c + 2] += w;
        }
      }
    }
    AddSource(axis == 2 ? s_theta : s_xy, a, sigma);
  }
}

// The walk: interval m of the grid (samples a to b) moves every error read at a sample j >= b,
// and a sample inside it by the fraction of the interval's time before it.
void AddWalk(const SensorNoise& noise, const TrackErrors& track,
             const std::vector<Interpolation>& at, Eigen::MatrixXd* sigma) {
  Eigen::VectorXd a(sigma->rows());
  const std::vector<Pose2d>& g = track.ground_truth;
  const std::vector<std::size_t> grid = WalkGrid(track.t_s);
  for (std::size_t m = 1; m < grid.size(); ++m) {
    const std::size_t ia = grid[m - 1], ib = grid[m];
    const double c0 = std::cos(g[ia].theta), s0 = std::sin(g[ia].theta);
    const double span = track.t_s[ib] - track.t_s[ia];
    for (int axis = 0; axis < 3; ++axis) {
      a.setZero();
      for (int c = 0; c < static_cast<int>(at.size()); ++c) {
        for (int h = 0; h < 2; ++h) {
          const std::size_t j = at[c].sample[h];
          if (at[c].weight[h] == 0.0 || j <= ia) continue;
          const double w =
              at[c].weight[h] * (j >= ib ? 1.0 : (track.t_s[j] - track.t_s[ia]) / span);
          if (axis == 0) {
            a[3 * c + 0] += w * c0;
            a[3 * c + 1] += w * s0;
          } else if (axis == 1) {
            a[3 * c + 0] -= w * s0;
            a[3 * c + 1] += w * c0;
          } else {
            a[3 * c + 0] -= w * (g[j].y - g[ib].y);
            a[3 * c + 1] += w * (g[j].x - g[ib].x);
            a[3 * c + 2] += w;
          }
        }
      }
      AddSource(noise.walk_var_per_interval[axis], a, sigma);
    }
  }
}

}  // namespace

Eigen::MatrixXd PropagateSensorNoise(const SensorNoise& noise, const TrackErrors& track,
                                     const std::vector<double>& times, double theta0) {
  const int rows = 3 * static_cast<int>(times.size());
  Eigen::MatrixXd sigma = Eigen::MatrixXd::Zero(rows, rows);
  if (track.t_s.empty()) return sigma;
  std::vector<Interpolation> at;
  for (double t : times) at.push_back(At(track, t));
  // The ground truth's position noise, taken as isotropic (the body axes' mean).
  const double s_xy = 0.5 * (noise.ground_truth_var[0] + noise.ground_truth_var[1]);
  const double s_theta = noise.ground_truth_var[2];
  AddGroundTruthNoise(s_xy, s_theta, at, &sigma);
  AddStartNoise(s_xy, s_theta, track.ground_truth, at, &sigma);
  AddWalk(noise, track, at, &sigma);
  // Into the start frame: every position pair turned by -theta0.
  Eigen::MatrixXd turn = Eigen::MatrixXd::Identity(rows, rows);
  const double c = std::cos(theta0), s = std::sin(theta0);
  for (int t = 0; t < static_cast<int>(times.size()); ++t) {
    turn.block<2, 2>(3 * t, 3 * t) << c, s, -s, c;
  }
  return turn * sigma * turn.transpose();
}

SensorFloorTest TestAgainstSensorFloor(const std::vector<Eigen::VectorXd>& e,
                                       const std::vector<Eigen::MatrixXd>& jacobian,
                                       const std::vector<Eigen::MatrixXd>& covariance,
                                       const std::vector<std::string>& group) {
  SensorFloorTest out;
  if (e.empty()) return out;
  const int num_parameters = static_cast<int>(jacobian.front().cols());
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(num_parameters, num_parameters);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(num_parameters);
  double total = 0.0, components = 0.0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    const Eigen::LLT<Eigen::MatrixXd> llt(covariance[i]);
    if (llt.info() != Eigen::Success) continue;  // a run the floor cannot weigh (no noise)
    const Eigen::VectorXd z = llt.matrixL().solve(e[i]);
    const Eigen::MatrixXd jz = llt.matrixL().solve(jacobian[i]);
    total += z.squaredNorm();
    normal += jz.transpose() * jz;
    rhs += jz.transpose() * z;
    components += static_cast<double>(e[i].size());
  }
  int identifiable = 0;
  const double explained = ExplainedByLinearisedRefit(normal, rhs, &identifiable);
  out.df = components - identifiable;
  if (!(out.df > 0.0)) return out;
  out.available = true;
  out.chi2 = std::max(0.0, total - explained);
  out.ratio = out.chi2 / out.df;
  out.p_value = stats::ChiSquareUpperTail(out.chi2, out.df);
  AddRepetitionCheck(e, covariance, group, &out);
  return out;
}

std::string SensorFloorFinding(const SensorFloorTest& test) {
  std::string out = StrFormat(
      "UNEXPLAINED: the residual is %.2f times what the sensors' noise explains (chi2 = %.1f on "
      "%.0f df, p = %.2g)",
      test.ratio, test.chi2, test.df, test.p_value);
  if (test.has_repetition_check && test.repetition_p_above < 0.01) {
    out += StrFormat(
        "; the repetitions scatter %.2f times it (p = %.2g): something changes from run to run "
        "beyond the sensors' noise",
        test.repetition_ratio, test.repetition_p_above);
  }
  return out;
}

std::string FormatSensorFloor(const SensorNoise& noise, const SensorFloorTest& test) {
  if (!noise.available) {
    return "sensor noise floor: not available (fewer than " + std::to_string(kMinIntervals) +
           " ground-truth intervals)\n";
  }
  std::string out = StrFormat(
      "sensor noise floor (from the residual track's high frequencies, %d intervals): ground "
      "truth %.2f mm / %.2f mm / %.3f deg, odometry walk %.2f mm / %.2f mm / %.3f deg per "
      "interval of >= 0.2 s (x / y body / heading, one sigma)\n",
      noise.num_intervals, 1e3 * std::sqrt(noise.ground_truth_var[0]),
      1e3 * std::sqrt(noise.ground_truth_var[1]), RadToDeg(std::sqrt(noise.ground_truth_var[2])),
      1e3 * std::sqrt(noise.walk_var_per_interval[0]),
      1e3 * std::sqrt(noise.walk_var_per_interval[1]),
      RadToDeg(std::sqrt(noise.walk_var_per_interval[2])));
  if (!test.available) return out + "residual against the sensor noise floor: not available\n";
  out += StrFormat(
      "residual against the sensor noise floor (every run, no repetitions needed): %.2f times "
      "it, chi2 = %.1f on %.0f df, p = %.2g\n",
      test.ratio, test.chi2, test.df, test.p_value);
  if (test.has_repetition_check) {
    out += StrFormat(
        "repetitions against the sensor noise floor: they scatter %.2f times it (%.0f df, p = "
        "%.2g that they scatter this much by the sensors' noise alone)\n",
        test.repetition_ratio, test.repetition_df, test.repetition_p_above);
    if (test.repetition_ratio < 0.5 && test.repetition_p_above > 0.999) {
      out +=
          "  (the floor is well above what the repetitions show: here the odometry's errors do not "
          "accumulate as a random walk - e.g. errors periodic in the wheel revolution - and the "
          "test against the floor is conservative)\n";
    }
  }
  return out;
}

}  // namespace fitcal
