#include "validation/trajectory_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fit/effect_fit.h"
#include "odometry/parallel_for.h"

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

// As the effect fit's track residual (effect_fit.h, StartAnchorIndices, FitAnchorCarry): the
// replay is moved rigidly so that it passes through the anchor ground-truth samples at the
// encoder times they show, whatever the log's start (at rest or moving). Returns the moved final
// pose.
Pose2d CarryThroughAnchors(const AlignedRun& run,
                           const std::vector<effects::SampleContext>& contexts,
                           const GroundTruthTrack& track, double latency_s,
                           const std::vector<double>& times, std::vector<Pose2d>* poses,
                           const Pose2d& final_pose) {
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
  std::vector<Pose2d> anchor_pose(anchors.size());
  for (std::size_t j = 0; j < anchors.size(); ++j) {
    anchor_pose[j] = odometry_at(track.t_s[anchors[j]] - latency_s);
  }
  const AnchorCarry<double> carried = FitAnchorCarry(track, anchors, anchor_pose);
  for (Pose2d& q : *poses) q = carried(q);
  return carried(final_pose);
}

// The odometry at every encoder time of a run's window: poses[k] at the time line's
// encoder_times[k], poses[0] the start pose. Heading stays unwrapped here; only errors are wrapped.
struct ReplayedRun {
  const std::vector<double>& times;
  std::vector<Pose2d> poses;
  Pose2d final_pose;
  Pose2d final_ground_truth;
  double latency_s = 0.0;  // a ground-truth latency effect: the sample stamped t shows t - tau
};

// The effect replay of any model's body step (odometry/effects.h), started where the effect fit
// starts it (TrackStartPose) and compared with the ground truth at t_final + latency.
template <typename Step>
void ReplayWithEffectList(const Step& step, const AlignedRun& run, const GroundTruthTrack& track,
                          const std::vector<effects::EffectValue>& effects, unsigned wheel_mask,
                          ReplayedRun* r) {
  std::vector<effects::ActiveEffect<double>> active;
  for (const effects::EffectValue& e : effects) active.push_back({e.id, e.value.data()});
  r->latency_s = effects::TotalLatency(active);
  const std::vector<effects::SampleContext> contexts =
      effects::MakeSampleContexts(run.samples, wheel_mask);
  r->poses[0] = TrackStartPose(run, contexts, track, r->latency_s);
  r->final_ground_truth = InterpolateGroundTruth(track, run.t_final_s + r->latency_s);
  r->final_pose = effects::ReplayStepsWithEffects(
      step, active, run.samples, contexts, r->poses[0],
      [r](std::size_t k, const Pose2d&, const Pose2d& after) { r->poses[k + 1] = after; });
  r->final_pose =
      CarryThroughAnchors(run, contexts, track, r->latency_s, r->times, &r->poses, r->final_pose);
}

TrajectoryErrors ErrorsAlongTrack(const AlignedRun& run, const GroundTruthTrack& track,
                                  const RunTimeLine& time_line, const ReplayedRun& replayed,
                                  OdometrySampling sampling);

}  // namespace

RunTimeLine::RunTimeLine(const AlignedRun& run, const GroundTruthTrack& track)
    : encoder_times(BoundaryTimes(run)) {
  // The track's times increase strictly (run_log.h): the samples inside are one stretch.
  const std::vector<double>& t_s = track.t_s;
  first = std::lower_bound(t_s.begin(), t_s.end(), run.t_start_s) - t_s.begin();
  end = std::max(first, static_cast<std::size_t>(
                            std::upper_bound(t_s.begin(), t_s.end(), run.t_final_s) - t_s.begin()));
}

TrajectoryErrors EvaluateTrajectory(const RobotModelInterface& model, const AlignedRun& run,
                                    const GroundTruthTrack& track, const std::vector<double>& p,
                                    const std::vector<effects::EffectValue>& effects,
                                    OdometrySampling sampling) {
  return EvaluateTrajectory(model, run, track, RunTimeLine(run, track), p, effects, sampling);
}

TrajectoryErrors EvaluateTrajectory(const RobotModelInterface& model, const AlignedRun& run,
                                    const GroundTruthTrack& track, const RunTimeLine& time_line,
                                    const std::vector<double>& p,
                                    const std::vector<effects::EffectValue>& effects,
                                    OdometrySampling sampling) {
  const std::size_t n = run.samples.size();
  if (time_line.encoder_times.size() != n + 1) {
    throw std::invalid_argument("run " + run.id +
                                ": EvaluateTrajectory given another run's time line");
  }
  ReplayedRun r{time_line.encoder_times, std::vector<Pose2d>(n + 1), {}, run.final_ground_truth};
  if (effects.empty()) {
    r.poses[0] = run.start;
    r.final_pose = model.Replay(p.data(), run.samples, 0, n, run.start,
                                [&r](std::size_t k, const Pose2d& pose) { r.poses[k + 1] = pose; });
  } else {
    const auto kinematics = model.PrepareKinematics(p.data());
    const auto step = [&kinematics](const double* w, double dt, double* dx, double* dy,
                                    double* dtheta) { kinematics->Step(w, dt, dx, dy, dtheta); };
    ReplayWithEffectList(step, run, track, effects, WheelChannelMask(model.robot()), &r);
  }
  return ErrorsAlongTrack(run, track, time_line, r, sampling);
}

namespace {

TrajectoryErrors ErrorsAlongTrack(const AlignedRun& run, const GroundTruthTrack& track,
                                  const RunTimeLine& time_line, const ReplayedRun& replayed,
                                  OdometrySampling sampling) {
  const std::vector<double>& times = replayed.times;
  const std::vector<Pose2d>& poses = replayed.poses;
  const std::size_t n = run.samples.size();
  const double latency_s = replayed.latency_s;
  const Pose2d& final_pose = replayed.final_pose;
  const Pose2d& final_ground_truth = replayed.final_ground_truth;
  TrajectoryErrors out;
  // The track's samples inside the window, one allocation each.
  const std::size_t first = time_line.first, end = time_line.end;
  out.t_s.assign(track.t_s.begin() + first, track.t_s.begin() + end);
  out.ground_truth.assign(track.world_T_robot.begin() + first, track.world_T_robot.begin() + end);
  out.odometry.reserve(end - first);
  out.distance_error_m.reserve(end - first);
  out.angle_error_rad.reserve(end - first);
  std::size_t hi = 0;
  for (std::size_t i = first; i < end; ++i) {
    const double t_enc = track.t_s[i] - latency_s;  // the encoder time this sample shows
    // The first encoder time at or after t_enc (std::lower_bound's, capped at n): both time lines
    // increase, so it only moves forward, one pass for the whole track (speed).
    while (hi < n && times[hi] < t_enc) ++hi;
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
    out.odometry.push_back(odom);
    // Eq. 8 as sqrt(dx^2 + dy^2), not std::hypot: errors in metres cannot overflow, so hypot's
    // scaling against it is not needed (speed; every fit scores this; equal up to rounding).
    const double dx = gt.x - odom.x, dy = gt.y - odom.y;
    out.distance_error_m.push_back(std::sqrt(dx * dx + dy * dy));               // Eq. 8
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

  // Final errors and CF exactly as Eq. 14 / models/pose_errors.h.
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

}  // namespace

FinalPoseErrors EvaluateFinalPoseErrors(const RobotModelInterface& model,
                                        const std::vector<double>& p,
                                        const std::vector<effects::EffectValue>& effects,
                                        const std::vector<AlignedRun>& runs,
                                        const std::vector<const GroundTruthTrack*>& tracks,
                                        int num_threads) {
  if (tracks.size() != runs.size()) {
    throw std::invalid_argument("EvaluateFinalPoseErrors: one ground-truth track per run");
  }
  std::vector<TrajectoryErrors> errors(runs.size());
  ParallelFor(runs.size(), num_threads, [&](std::size_t i) {
    errors[i] = EvaluateTrajectory(model, runs[i], *tracks[i], p, effects);
  });
  FinalPoseErrors out;
  for (const TrajectoryErrors& e : errors) {
    out.per_run_cf.push_back(e.cf);
    out.cf += e.cf;
    out.mean_position_error_m += e.final_distance_m;
    out.mean_abs_heading_error_rad += e.final_angle_rad;
  }
  if (!runs.empty()) {
    const double n = static_cast<double>(runs.size());
    out.cf /= n;
    out.mean_position_error_m /= n;
    out.mean_abs_heading_error_rad /= n;
  }
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

TrajectoryErrors AverageOf(const std::vector<const TrajectoryErrors*>& runs) {
  TrajectoryErrors a;
  if (runs.empty()) return a;
  for (double TrajectoryErrors::*field :
       {&TrajectoryErrors::rms_distance_m, &TrajectoryErrors::rms_angle_rad,
        &TrajectoryErrors::max_distance_m, &TrajectoryErrors::max_angle_rad,
        &TrajectoryErrors::final_distance_m, &TrajectoryErrors::final_angle_rad,
        &TrajectoryErrors::cf}) {
    for (const TrajectoryErrors* r : runs) a.*field += r->*field;
    a.*field /= static_cast<double>(runs.size());
  }
  return a;
}

double ImprovementPercent(double before, double after) {
  return before > 0.0 ? 100.0 * (before - after) / before : 0.0;
}

}  // namespace fitcal
