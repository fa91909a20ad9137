#include "validation/odometry_covariance.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "odometry/aligned_run.h"
#include "odometry/pose_between.h"

namespace fitcal {
namespace {

// The ground truth's heading at a window's start is averaged over +-this (its noise would
// otherwise rotate the window's displacement: a position error growing with the window).
constexpr double kHeadingSmoothingS = 0.05;
constexpr int kHeadingSmoothingSteps = 5;
// Lags of the structure function (encoder samples) and the path windows of the pose law (m).
constexpr int kLags[] = {1, 2, 4, 8, 16, 32, 64, 128, 256};
constexpr double kPathWindowsM[] = {0.25, 0.5, 1.0, 2.0, 4.0};
// A mean square over fewer windows than this does not enter a fit.
constexpr std::size_t kMinWindows = 10;

// One run replayed once from the identity: the pose, time and odometry path at every sample
// boundary (index k: after k samples).
struct ReplayedRun {
  const RunLog* log = nullptr;
  std::vector<Pose2d> pose;
  std::vector<double> t_s, path_m;
};

ReplayedRun ReplayRun(const RobotModelInterface& model, const std::vector<double>& p,
                      const RunLog& log, const AlignedRun& run) {
  ReplayedRun out;
  out.log = &log;
  out.pose.push_back(Pose2d{});
  out.t_s = BoundaryTimes(run);
  out.path_m.push_back(0.0);
  model.Replay(p.data(), run.samples, 0, run.samples.size(), Pose2d{},
               [&](std::size_t, const Pose2d& pose) {
                 out.path_m.push_back(out.path_m.back() + std::hypot(pose.x - out.pose.back().x,
                                                                     pose.y - out.pose.back().y));
                 out.pose.push_back(pose);
               });
  return out;
}

// The ground truth at t with its heading averaged over +-kHeadingSmoothingS.
Pose2d SmoothedGroundTruth(const GroundTruthTrack& track, double t) {
  const Pose2d centre = InterpolateGroundTruth(track, t);
  double sum = 0.0;
  for (int i = -kHeadingSmoothingSteps; i <= kHeadingSmoothingSteps; ++i) {
    const double ti = t + kHeadingSmoothingS * i / kHeadingSmoothingSteps;
    sum += WrapAngle(InterpolateGroundTruth(track, ti).theta - centre.theta);
  }
  Pose2d out = centre;
  out.theta += sum / (2 * kHeadingSmoothingSteps + 1);
  return out;
}

// The odometry's error over samples [b, e): its displacement against the ground truth's in the
// (smoothed) ground-truth frame at the start; the heading error against the raw headings.
std::array<double, 3> WindowError(const ReplayedRun& r, std::size_t b, std::size_t e) {
  const Pose2d odometry = Between(r.pose[b], r.pose[e]);
  const GroundTruthTrack& track = r.log->ground_truth;
  const Pose2d start = SmoothedGroundTruth(track, r.t_s[b]);
  const Pose2d end = InterpolateGroundTruth(track, r.t_s[e]);
  const Pose2d truth = Between(start, end);
  const double truth_turn = end.theta - InterpolateGroundTruth(track, r.t_s[b]).theta;
  return {odometry.x - truth.x, odometry.y - truth.y, WrapAngle(odometry.theta - truth_turn)};
}

// Mean squares per axis and their window count.
struct MeanSquares {
  std::array<double, 3> sum{};
  std::size_t count = 0;
  double extent = 0.0;  // summed duration (s) or path (m) of the windows
  void Add(const std::array<double, 3>& e, double window_extent) {
    for (int a = 0; a < 3; ++a) sum[a] += e[a] * e[a];
    extent += window_extent;
    ++count;
  }
  double Mean(int a) const { return count > 0 ? sum[a] / count : 0.0; }
};

// Quantisation's variance of a window's error per axis: a tick's uniform uncertainty at either
// end of each wheel channel, (2 pi / N)^2 / 12 twice, carried into the body displacement by the
// model's one-sample Jacobian (finite differences, averaged over the run's samples).
std::array<double, 3> QuantisationVariance(const RobotModelInterface& model,
                                           const std::vector<double>& p,
                                           const std::vector<AlignedRun>& runs) {
  const Robot& robot = model.robot();
  std::array<double, 3> out{};
  if (!robot.encoder || !(robot.encoder->ticks_per_rev > 0.0)) return out;
  const double step_rad = 2.0 * M_PI / robot.encoder->ticks_per_rev;
  const double end_variance = step_rad * step_rad / 12.0;
  std::size_t used = 0;
  for (const AlignedRun& run : runs) {
    for (std::size_t k = 0; k < run.samples.size(); k += 25) {
      const ConstSampleView s = run.samples[k];
      if (!(s.dt_s > 0.0)) continue;
      const int n = run.samples.num_channels();
      EncoderSamples one(n);
      one.push_back(s);
      const Pose2d base = model.Replay(p.data(), one, 0, 1, Pose2d{});
      for (int c = 0; c < n; ++c) {
        if (robot.channels[c].kind != ChannelKind::kWheelRate) continue;
        EncoderSamples moved = one;
        moved[0].value[c] += step_rad / s.dt_s;  // one tick more over the interval
        const Pose2d d = Between(base, model.Replay(p.data(), moved, 0, 1, Pose2d{}));
        const double per_rad[3] = {d.x / step_rad, d.y / step_rad, d.theta / step_rad};
        for (int a = 0; a < 3; ++a) out[a] += 2.0 * end_variance * per_rad[a] * per_rad[a];
      }
      ++used;
    }
  }
  for (double& v : out) v = used > 0 ? v / used : 0.0;
  return out;
}

// The ground truth's own noise variance per axis (m^2, m^2, rad^2) from its second differences
// at its own rate: for a smooth motion x(t-h) - 2 x(t) + x(t+h) is the noise, of variance 6 s^2
// (the motion adds a h^2, small at motion-capture rates; it can only make the estimate larger).
std::array<double, 3> GroundTruthNoise(const std::vector<RunLog>& runs) {
  std::array<double, 3> sum{};
  std::size_t count = 0;
  for (const RunLog& log : runs) {
    const std::vector<Pose2d>& q = log.ground_truth.world_T_robot;
    for (std::size_t k = 1; k + 1 < q.size(); ++k) {
      const double dx = q[k - 1].x - 2.0 * q[k].x + q[k + 1].x;
      const double dy = q[k - 1].y - 2.0 * q[k].y + q[k + 1].y;
      const double dth =
          WrapAngle(q[k - 1].theta - q[k].theta) + WrapAngle(q[k + 1].theta - q[k].theta);
      // Position noise is isotropic: either world axis serves for both body axes.
      sum[0] += 0.5 * (dx * dx + dy * dy);
      sum[2] += dth * dth;
      ++count;
    }
  }
  if (count == 0) return sum;
  sum[0] /= 6.0 * count;
  sum[2] /= 6.0 * count;
  sum[1] = sum[0];
  return sum;
}

double MedianGroundTruthInterval(const std::vector<RunLog>& runs) {
  std::vector<double> dt;
  for (const RunLog& log : runs) {
    const std::vector<double>& t = log.ground_truth.t_s;
    for (std::size_t k = 1; k < t.size(); ++k) dt.push_back(t[k] - t[k - 1]);
  }
  if (dt.empty()) return 0.0;
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return dt[dt.size() / 2];
}

double MedianInterval(const std::vector<AlignedRun>& runs) {
  std::vector<double> dt;
  for (const AlignedRun& run : runs) {
    for (const ConstSampleView s : run.samples) dt.push_back(s.dt_s);
  }
  if (dt.empty()) return 0.0;
  std::nth_element(dt.begin(), dt.begin() + dt.size() / 2, dt.end());
  return dt[dt.size() / 2];
}

// V(d) = a d^p through the points with positive V (least squares in logs); p = 1 from one point.
std::pair<double, double> PowerLaw(const std::vector<double>& d, const std::vector<double>& v) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (v[i] > 0.0) {
      x.push_back(std::log(d[i]));
      y.push_back(std::log(v[i]));
    }
  }
  if (x.empty()) return {0.0, 1.0};
  if (x.size() == 1) return {std::exp(y[0] - x[0]), 1.0};
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i] / x.size();
    my += y[i] / x.size();
  }
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  const double slope = sxx > 0.0 ? sxy / sxx : 1.0;
  return {std::exp(my - slope * mx), slope};
}

}  // namespace

namespace {

// Best non-negative fit of V(T) = c + beta T + alpha T^2 with the terms in `allowed` (bits 0-2).
std::array<double, 3> FitTerms(const std::vector<double>& t, const std::vector<double>& v,
                               const std::vector<double>& w, int allowed) {
  std::array<double, 3> best{};
  double best_cost = HUGE_VAL;
  for (int subset = 1; subset < 8; ++subset) {
    if ((subset & ~allowed) != 0) continue;
    std::vector<int> columns;
    for (int c = 0; c < 3; ++c) {
      if (subset & (1 << c)) columns.push_back(c);
    }
    Eigen::MatrixXd a(t.size(), columns.size());
    Eigen::VectorXd b(t.size());
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double sw = std::sqrt(w[i]);
      for (std::size_t c = 0; c < columns.size(); ++c) a(i, c) = sw * std::pow(t[i], columns[c]);
      b(i) = sw * v[i];
    }
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
    if ((x.array() < 0.0).any() || !x.allFinite()) continue;
    const double cost = (a * x - b).squaredNorm();
    if (cost >= best_cost) continue;
    best_cost = cost;
    best = {};
    for (std::size_t c = 0; c < columns.size(); ++c) best[columns[c]] = x(c);
  }
  return best;
}

// beta T + alpha T^2 only (the intercept known); alpha T^2 alone when the encoders count ticks:
// their white error is the quantisation, known, and a beta fitted on top would be the intercept's
// error / T, which beta / dt multiplies by T / dt (a 0.5 % error in the ground truth's noise
// variance made the per-message vx sigma 5x too large on the independent simulator).
std::array<double, 3> FitGrowth(const std::vector<double>& t, const std::vector<double>& v,
                                const std::vector<double>& w, bool ticks) {
  return FitTerms(t, v, w, ticks ? 0b100 : 0b110);
}

// What a mean square V of n Gaussian errors could hide: two of its standard errors, V sqrt(2 / n).
double TwoStandardErrors(double mean_square, double n) {
  return 2.0 * mean_square * std::sqrt(2.0 / n);
}

// The white growth (per second) that the windows could hide where they resolve none: two
// standard errors of a lag's mean square (n = w V^2, the weights above) over its duration, the
// tightest over the lags. Zero growth is not zero error: an EKF given a twist variance of 0
// trusts the twist exactly.
double UnresolvedGrowthBound(const std::vector<double>& t, const std::vector<double>& v,
                             const std::vector<double>& w) {
  double bound = HUGE_VAL;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (!(w[i] > 0.0 && v[i] > 0.0 && t[i] > 0.0)) continue;
    bound = std::min(bound, TwoStandardErrors(v[i], w[i] * v[i] * v[i]) / t[i]);
  }
  return std::isfinite(bound) ? bound : 0.0;
}

}  // namespace

std::array<double, 3> FitStructureFunction(const std::vector<double>& t,
                                           const std::vector<double>& v,
                                           const std::vector<double>& w) {
  return FitTerms(t, v, w, 0b111);
}

OdometryCovariance EstimateOdometryCovariance(const RobotModelInterface& model,
                                              const std::vector<double>& p,
                                              const std::vector<RunLog>& runs, double interval_s) {
  OdometryCovariance out;
  std::vector<AlignedRun> aligned;
  for (const RunLog& log : runs) aligned.push_back(AlignRun(log));
  out.interval_s = interval_s > 0.0 ? interval_s : MedianInterval(aligned);
  out.runs = runs.size();
  std::vector<ReplayedRun> replayed;
  for (std::size_t i = 0; i < runs.size(); ++i)
    replayed.push_back(ReplayRun(model, p, runs[i], aligned[i]));
  out.quantisation_variance = QuantisationVariance(model, p, aligned);
  // The structure function over time lags.
  std::vector<MeanSquares> by_lag;
  const double shortest_s = 2.0 * MedianGroundTruthInterval(runs);
  for (int lag : kLags) {
    MeanSquares m;
    for (const ReplayedRun& r : replayed) {
      for (std::size_t b = 0; b + lag < r.pose.size(); b += lag)
        m.Add(WindowError(r, b, b + lag), r.t_s[b + lag] - r.t_s[b]);
    }
    // A window shorter than two ground-truth intervals reads the ground truth between the same
    // few samples at both ends: their noise cancels there, and would pass for growth.
    if (m.count >= kMinWindows && m.extent / m.count >= shortest_s)
      by_lag.push_back(m);
  }
  if (by_lag.empty() || !(out.interval_s > 0.0)) return out;
  out.windows = by_lag.front().count;
  const double dt = out.interval_s;
  const std::array<double, 3> noise = GroundTruthNoise(runs);
  const bool ticks = model.robot().encoder && model.robot().encoder->ticks_per_rev > 0.0;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> t, v, w;
    for (const MeanSquares& m : by_lag) {
      t.push_back(m.extent / m.count);
      v.push_back(m.Mean(a));
      // A mean square of n Gaussian errors has variance 2 V^2 / n.
      w.push_back(m.Mean(a) > 0.0 ? m.count / (m.Mean(a) * m.Mean(a)) : 0.0);
    }
    // The intercept c: the ground truth's noise, the smaller of its own estimate and what the
    // structure function says, plus the quantisation. Only beta and alpha are then fitted, on
    // what remains: at one message the odometry's error is far below the ground truth's noise,
    // so an intercept fitted freely would leak its error into beta / dt.
    const std::array<double, 3> free = FitStructureFunction(t, v, w);
    out.ground_truth_variance[a] = std::min(
        noise[a], std::max(0.0, free[0] - out.quantisation_variance[a]) / 2.0);
    const double c = 2.0 * out.ground_truth_variance[a] + out.quantisation_variance[a];
    std::vector<double> remaining;
    for (double x : v) remaining.push_back(x - c);
    const std::array<double, 3> f = FitGrowth(t, remaining, w, ticks);
    out.twist_variance[a] = (f[1] * dt + f[2] * dt * dt + out.quantisation_variance[a]) / (dt * dt);
    if (!(out.twist_variance[a] > 0.0)) {  // a simulated bag's omega: 0 (export, stop 70)
      out.twist_variance[a] = UnresolvedGrowthBound(t, v, w) / dt;
      out.twist_unresolved[a] = true;
    }
  }
  // The pose law over path windows, the ground truth's noise removed.
  std::vector<double> d;
  std::array<std::vector<double>, 3> v;
  std::array<double, 3> hidden_at_1m{HUGE_VAL, HUGE_VAL, HUGE_VAL};
  bool measured_at_1m = false;
  for (double length : kPathWindowsM) {
    MeanSquares m;
    for (const ReplayedRun& r : replayed) {
      std::size_t b = 0;
      for (std::size_t e = 1; e < r.pose.size(); ++e) {
        if (r.path_m[e] - r.path_m[b] < length) continue;
        m.Add(WindowError(r, b, e), r.path_m[e] - r.path_m[b]);
        b = e;
      }
    }
    if (m.count < kMinWindows) continue;
    d.push_back(m.extent / m.count);  // the windows' mean path
    for (int a = 0; a < 3; ++a) {
      v[a].push_back(m.Mean(a) - 2.0 * out.ground_truth_variance[a]);
      // What the windows could hide, taken to 1 m as a random walk: the bound of an axis they
      // resolve nothing on. The 1 m windows' where there are, else the tightest length's.
      const double hidden = TwoStandardErrors(m.Mean(a), m.count) / d.back();
      if (length == 1.0) {
        hidden_at_1m[a] = hidden;
      } else if (!measured_at_1m) {
        hidden_at_1m[a] = std::min(hidden_at_1m[a], hidden);
      }
    }
    if (length == 1.0) {  // the controller's constant, where the data measure it directly
      measured_at_1m = true;
      for (int a = 0; a < 3; ++a) out.pose_variance_1m[a] = v[a].back();
    }
  }
  for (int a = 0; a < 3; ++a) {
    const auto [at_1m, exponent] = PowerLaw(d, v[a]);
    if (!measured_at_1m || !(out.pose_variance_1m[a] > 0.0)) out.pose_variance_1m[a] = at_1m;
    // A variance does not shrink with the path: a negative slope is growth the windows do not
    // resolve beside the ground truth's noise (a simulated bag's heading: -0.33). Flat, then.
    out.pose_growth_exponent[a] = std::max(0.0, exponent);
    // Zero error is not what the windows showed: an EKF given a pose variance of 0 trusts it
    // exactly (a simulated bag's noise-free encoders: x and theta 0).
    if (!(out.pose_variance_1m[a] > 0.0) && std::isfinite(hidden_at_1m[a])) {
      out.pose_variance_1m[a] = hidden_at_1m[a];
      out.pose_unresolved[a] = true;
    }
  }
  return out;
}

}  // namespace fitcal
