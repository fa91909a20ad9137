#include "validation/odometry_covariance.h"

#include <cmath>

#include "odometry/aligned_run.h"

namespace fitcal {
namespace {

// A run shorter than this travelled too little to scale a pose error by its path.
constexpr double kMinPathM = 0.01;

// The error of `odometry` against `truth`, in the robot frame of `frame` (heading wrapped).
std::array<double, 3> ErrorInFrame(const Pose2d& frame, const Pose2d& odometry,
                                   const Pose2d& truth) {
  const double c = std::cos(frame.theta), s = std::sin(frame.theta);
  const double dx = odometry.x - truth.x, dy = odometry.y - truth.y;
  return {c * dx + s * dy, -s * dx + c * dy, WrapAngle(odometry.theta - truth.theta)};
}

// Window errors of one aligned run: consecutive windows of at least window_s, each replayed from
// the ground truth at its start (the sample boundaries are the only times the odometry has).
void AddTwistErrors(const RobotModelInterface& model, const std::vector<double>& p,
                    const RunLog& log, const AlignedRun& run, double window_s,
                    OdometryErrors* out) {
  std::size_t begin = 0;
  double t0 = run.t_start_s;
  while (begin < run.samples.size()) {
    std::size_t end = begin;
    double t1 = t0;
    while (end < run.samples.size() && t1 - t0 < window_s) t1 += run.samples[end++].dt_s;
    if (t1 - t0 < window_s) return;  // the run's tail, shorter than a window
    const Pose2d start = InterpolateGroundTruth(log.ground_truth, t0);
    const Pose2d odometry = model.Replay(p.data(), run.samples, begin, end, start);
    const std::array<double, 3> e =
        ErrorInFrame(start, odometry, InterpolateGroundTruth(log.ground_truth, t1));
    const double duration_s = t1 - t0;
    out->twist.push_back({e[0] / duration_s, e[1] / duration_s, e[2] / duration_s});
    begin = end;
    t0 = t1;
  }
}

}  // namespace

OdometryErrors CollectOdometryErrors(const RobotModelInterface& model,
                                     const std::vector<double>& p,
                                     const std::vector<RunLog>& runs, double window_s) {
  OdometryErrors out;
  for (const RunLog& log : runs) {
    const AlignedRun run = AlignRun(log);
    AddTwistErrors(model, p, log, run, window_s, &out);
    double path_m = 0.0;
    Pose2d previous = run.start;
    const Pose2d final_pose =
        model.Replay(p.data(), run.samples, 0, run.samples.size(), run.start,
                     [&](std::size_t, const Pose2d& pose) {
                       path_m += std::hypot(pose.x - previous.x, pose.y - previous.y);
                       previous = pose;
                     });
    if (path_m < kMinPathM) continue;
    out.pose.push_back(ErrorInFrame(run.start, final_pose, run.final_ground_truth));
    out.path_m.push_back(path_m);
  }
  return out;
}

OdometryCovariance EstimateOdometryCovariance(const OdometryErrors& errors, double window_s) {
  OdometryCovariance c;
  c.window_s = window_s;
  c.windows = errors.twist.size();
  c.runs = errors.pose.size();
  for (const std::array<double, 3>& e : errors.twist) {
    for (int a = 0; a < 3; ++a) c.twist_variance[a] += e[a] * e[a] / c.windows;
  }
  for (std::size_t i = 0; i < errors.pose.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      c.pose_variance_per_m[a] += errors.pose[i][a] * errors.pose[i][a] / errors.path_m[i] / c.runs;
    }
  }
  return c;
}

OdometryCoverage CoverageOf(const OdometryCovariance& covariance, const OdometryErrors& errors) {
  OdometryCoverage out;
  std::size_t twist1 = 0, twist2 = 0, pose1 = 0, pose2 = 0;
  for (const std::array<double, 3>& e : errors.twist) {
    for (int a = 0; a < 3; ++a) {
      const double sigma = std::sqrt(covariance.twist_variance[a]);
      twist1 += std::abs(e[a]) <= sigma;
      twist2 += std::abs(e[a]) <= 2.0 * sigma;
    }
  }
  for (std::size_t i = 0; i < errors.pose.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const double sigma = std::sqrt(covariance.pose_variance_per_m[a] * errors.path_m[i]);
      pose1 += std::abs(errors.pose[i][a]) <= sigma;
      pose2 += std::abs(errors.pose[i][a]) <= 2.0 * sigma;
    }
  }
  out.twist_samples = 3 * errors.twist.size();
  out.pose_samples = 3 * errors.pose.size();
  const auto share = [](std::size_t n, std::size_t of) {
    return of > 0 ? static_cast<double>(n) / static_cast<double>(of) : 0.0;
  };
  out.twist_within_1_sigma = share(twist1, out.twist_samples);
  out.twist_within_2_sigma = share(twist2, out.twist_samples);
  out.pose_within_1_sigma = share(pose1, out.pose_samples);
  out.pose_within_2_sigma = share(pose2, out.pose_samples);
  return out;
}

}  // namespace fitcal
