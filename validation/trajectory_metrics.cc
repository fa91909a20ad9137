#include "validation/trajectory_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "diagnosis/effect_fit.h"
#include "odometry/omni3_replay.h"

namespace fitcal {

const char* ToString(OdometrySampling sampling) {
  switch (sampling) {
    case OdometrySampling::kNearestTime:
      return "nearest";
    case OdometrySampling::kLinearInterpolation:
      return "linear";
  }
  return "?";
}

namespace {

// As the effect fit's track residual (effect_fit.h, StartAnchorIndices): the replay is moved
// rigidly so that it passes through the anchor ground-truth samples at the encoder times they
// show (least squares), whatever the log's start (at rest or moving). Returns the moved final
// pose.
Pose2d CarryThroughAnchors(const AlignedRun& run, const GroundTruthTrack& track, double latency_s,
                           const std::vector<double>& times, std::vector<Pose2d>* poses,
                           const Pose2d& final_pose) {
  const std::vector<effects::SampleContext> contexts = effects::MakeSampleContexts(run.samples);
  const std::vector<int> anchors = StartAnchorIndices(run, contexts, track, latency_s);
  if (anchors.empty() || times.size() < 2) return final_pose;
  const auto odometry_at = [&](double e) {
    const std::size_t hi = std::clamp<std::size_t>(
        static_cast<std::size_t>(std::lower_bound(times.begin(), times.end(), e) - times.begin()),
        1, times.size() - 1);
    const std::size_t lo = hi - 1;
    const double u = std::clamp((e - times[lo]) / (times[hi] - times[lo]), 0.0, 1.0);
    const Pose2d& a = (*poses)[lo];
    const Pose2d& b = (*poses)[hi];
    return Pose2d{a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.theta + u * (b.theta - a.theta)};
  };
  std::vector<Pose2d> p(anchors.size());
  const double m = static_cast<double>(anchors.size());
  double turn = 0.0, d0 = 0.0;
  for (std::size_t j = 0; j < anchors.size(); ++j) {
    p[j] = odometry_at(track.t_s[anchors[j]] - latency_s);
    const double d = track.world_T_robot[anchors[j]].theta - p[j].theta;
    if (j == 0) d0 = d;
    turn += (d0 + WrapAngle(d - d0)) / m;
  }
  const double c = std::cos(turn), s = std::sin(turn);
  double cx = 0.0, cy = 0.0;
  for (std::size_t j = 0; j < anchors.size(); ++j) {
    const Pose2d& g = track.world_T_robot[anchors[j]];
    cx += (g.x - (c * p[j].x - s * p[j].y)) / m;
    cy += (g.y - (s * p[j].x + c * p[j].y)) / m;
  }
  const auto carried = [&](const Pose2d& q) {
    return Pose2d{cx + c * q.x - s * q.y, cy + s * q.x + c * q.y, q.theta + turn};
  };
  for (Pose2d& q : *poses) q = carried(q);
  return carried(final_pose);
}

}  // namespace

TrajectoryErrors EvaluateTrajectory(const AlignedRun& run, const GroundTruthTrack& track,
                                    const Omni3ParameterArray& p, OdometrySampling sampling) {
  return EvaluateTrajectory(run, track, p, {}, sampling);
}

TrajectoryErrors EvaluateTrajectory(const AlignedRun& run, const GroundTruthTrack& track,
                                    const Omni3ParameterArray& p,
                                    const std::vector<effects::EffectValue>& effects,
                                    OdometrySampling sampling) {
  // The odometry at every encoder time of the window: times[0] = t_start with the start pose,
  // times[k + 1] after sample k (Eq. 4). Heading stays unwrapped here; only errors are wrapped.
  const std::size_t n = run.samples.size();
  std::vector<double> times(n + 1);
  std::vector<Pose2d> poses(n + 1);
  times[0] = run.t_start_s;
  double t = run.t_start_s;
  for (std::size_t k = 0; k < n; ++k) {
    t += run.samples[k].dt_s;
    times[k + 1] = t;
  }
  Pose2d final_pose;
  Pose2d final_ground_truth = run.final_ground_truth;
  double latency_s = 0.0;
  if (effects.empty()) {
    poses[0] = run.start;
    final_pose = omni3::ReplayWithMatrix(
        omni3::InverseKinematicMatrix(p.data()), run.samples, 0, n, run.start,
        [&poses](std::size_t k, const Pose2d& pose) { poses[k + 1] = pose; });
  } else {
    std::vector<effects::ActiveEffect<double>> active;
    for (const effects::EffectValue& e : effects) active.push_back({e.id, e.value.data()});
    latency_s = effects::TotalLatency(active);
    const std::vector<effects::SampleContext> contexts = effects::MakeSampleContexts(run.samples);
    poses[0] = TrackStartPose(run, contexts, track, latency_s);
    final_ground_truth = InterpolateGroundTruth(track, run.t_final_s + latency_s);
    final_pose = effects::ReplayWithEffects(
        p.data(), active, run.samples, contexts, poses[0],
        [&poses](std::size_t k, const Pose2d&, const Pose2d& after) { poses[k + 1] = after; });
    final_pose = CarryThroughAnchors(run, track, latency_s, times, &poses, final_pose);
  }

  TrajectoryErrors out;
  for (std::size_t i = 0; i < track.t_s.size(); ++i) {
    const double t_gt = track.t_s[i];
    if (t_gt < run.t_start_s || t_gt > run.t_final_s) continue;
    const double t_enc = t_gt - latency_s;  // the encoder time this sample shows
    const std::size_t hi = std::min<std::size_t>(
        static_cast<std::size_t>(std::lower_bound(times.begin(), times.end(), t_enc) -
                                 times.begin()),
        n);
    const std::size_t lo = hi == 0 ? 0 : hi - 1;
    Pose2d odom;
    if (hi == lo || times[hi] <= times[lo]) {
      odom = poses[hi];
    } else if (sampling == OdometrySampling::kNearestTime) {
      odom = (t_enc - times[lo] <= times[hi] - t_enc) ? poses[lo] : poses[hi];
    } else {
      const double u = std::clamp((t_enc - times[lo]) / (times[hi] - times[lo]), 0.0, 1.0);
      odom = Pose2d{poses[lo].x + u * (poses[hi].x - poses[lo].x),
                    poses[lo].y + u * (poses[hi].y - poses[lo].y),
                    poses[lo].theta + u * (poses[hi].theta - poses[lo].theta)};
    }
    const Pose2d& gt = track.world_T_robot[i];
    out.t_s.push_back(t_gt);
    out.ground_truth.push_back(gt);
    out.odometry.push_back(odom);
    out.distance_error_m.push_back(std::hypot(gt.x - odom.x, gt.y - odom.y));   // Eq. 8
    out.angle_error_rad.push_back(std::abs(WrapAngle(gt.theta - odom.theta)));  // Eq. 9
  }
  if (out.t_s.empty()) {
    throw std::invalid_argument("run " + run.id +
                                ": no ground-truth sample inside the encoder time window");
  }
  const double m = static_cast<double>(out.t_s.size());
  double sum_d2 = 0.0, sum_a2 = 0.0;
  for (std::size_t i = 0; i < out.t_s.size(); ++i) {
    sum_d2 += out.distance_error_m[i] * out.distance_error_m[i];
    sum_a2 += out.angle_error_rad[i] * out.angle_error_rad[i];
    out.max_distance_m = std::max(out.max_distance_m, out.distance_error_m[i]);  // Eq. 10
    out.max_angle_rad = std::max(out.max_angle_rad, out.angle_error_rad[i]);     // Eq. 11
  }
  out.rms_distance_m = std::sqrt(sum_d2 / m);  // Eq. 12
  out.rms_angle_rad = std::sqrt(sum_a2 / m);   // Eq. 13

  // Final errors and CF exactly as Eq. 14 / final_pose_residual.h.
  out.final_odometry = final_pose;
  out.final_ground_truth = final_ground_truth;
  const double dx = final_pose.x - final_ground_truth.x;
  const double dy = final_pose.y - final_ground_truth.y;
  const double dtheta = WrapAngle(final_pose.theta - final_ground_truth.theta);
  out.final_distance_m = std::hypot(dx, dy);
  out.final_angle_rad = std::abs(dtheta);
  out.cf = std::sqrt(dx * dx + dy * dy + dtheta * dtheta);
  return out;
}

SummaryStatistics Summarize(std::vector<double> values) {
  SummaryStatistics s;
  if (values.empty()) return s;
  const double n = static_cast<double>(values.size());
  s.count = static_cast<int>(values.size());
  std::sort(values.begin(), values.end());
  double sum = 0.0, sum2 = 0.0;
  for (double v : values) {
    sum += v;
    sum2 += v * v;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sum2 / n);
  double var = 0.0;
  for (double v : values) var += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(var / n);
  const std::size_t mid = values.size() / 2;
  s.median = values.size() % 2 == 1 ? values[mid] : 0.5 * (values[mid - 1] + values[mid]);
  s.min = values.front();
  s.max = values.back();
  return s;
}

Table6Averages AverageOf(const std::vector<const TrajectoryErrors*>& runs) {
  Table6Averages a;
  if (runs.empty()) return a;
  for (const TrajectoryErrors* r : runs) {
    a.rms_distance_m += r->rms_distance_m;
    a.rms_angle_rad += r->rms_angle_rad;
    a.max_distance_m += r->max_distance_m;
    a.max_angle_rad += r->max_angle_rad;
    a.final_distance_m += r->final_distance_m;
    a.final_angle_rad += r->final_angle_rad;
    a.cf += r->cf;
  }
  const double n = static_cast<double>(runs.size());
  a.rms_distance_m /= n;
  a.rms_angle_rad /= n;
  a.max_distance_m /= n;
  a.max_angle_rad /= n;
  a.final_distance_m /= n;
  a.final_angle_rad /= n;
  a.cf /= n;
  return a;
}

double ImprovementPercent(double before, double after) {
  return before > 0.0 ? 100.0 * (before - after) / before : 0.0;
}

}  // namespace fitcal
