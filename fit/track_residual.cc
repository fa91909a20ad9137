#include "fit/track_residual.h"

#include <ceres/jet.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "fit/segment_cost.h"

namespace fitcal {

bool TrackResidualOptions::IsValid(std::string* error) const {
  if (!(checkpoint_spacing_m > 0.0) || !(huber_scale > 0.0) || !(max_clock_offset_s >= 0.0)) {
    *error = "track: checkpoint spacing and loss scale must be positive, the offset bound >= 0";
    return false;
  }
  return true;
}

// H: kMinSmoothingHalfWidthS, or two median sample intervals where the ground truth is sparser,
// so that a few samples always share the window.
double SmoothingHalfWidth(const GroundTruthTrack& track) {
  std::vector<double> intervals;
  for (std::size_t k = 1; k < track.t_s.size(); ++k) intervals.push_back(track.t_s[k] - track.t_s[k - 1]);
  if (intervals.empty()) return kMinSmoothingHalfWidthS;
  std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
  return std::max(kMinSmoothingHalfWidthS, 2.0 * intervals[intervals.size() / 2]);
}

TrackCheckpoints MakeTrackCheckpoints(const AlignedRun& run, const GroundTruthTrack& ground_truth,
                                      const TrackResidualOptions& options) {
  TrackCheckpoints out;
  out.run = &run;
  out.ground_truth = &ground_truth;
  out.t_start_s = run.t_start_s;
  out.smoothing_half_width_s = SmoothingHalfWidth(ground_truth);
  out.segments = MakeCheckpointsFromStart(run, ground_truth, options.checkpoint_spacing_m);
  double t = run.t_start_s;
  std::size_t done = 0;
  for (const Segment& s : out.segments) {
    for (; done < s.end; ++done) t += run.samples[done].dt_s;
    out.t_s.push_back(t);
  }
  return out;
}

const char* ToString(ClockGrouping grouping) {
  switch (grouping) {
    case ClockGrouping::kPerSession:
      return "session";
    case ClockGrouping::kPerRun:
      return "run";
    case ClockGrouping::kDataset:
      return "dataset";
    case ClockGrouping::kNone:
      return "none";
  }
  return "?";
}

bool ParseClockGrouping(const std::string& text, ClockGrouping* out) {
  for (ClockGrouping g : {ClockGrouping::kPerSession, ClockGrouping::kPerRun,
                          ClockGrouping::kDataset, ClockGrouping::kNone}) {
    if (text == ToString(g)) {
      *out = g;
      return true;
    }
  }
  return false;
}

std::string ClockGroupOf(const std::string& run_id, const std::string& trajectory,
                         ClockGrouping grouping) {
  if (grouping == ClockGrouping::kPerRun) return run_id;
  if (grouping == ClockGrouping::kPerSession) return trajectory;
  return "all";
}

int ShiftGroundTruthClocks(const std::vector<std::pair<std::string, double>>& offset_of_group,
                           ClockGrouping grouping, std::vector<RunLog>* logs) {
  int moved = 0;
  for (RunLog& log : *logs) {
    const std::string group = ClockGroupOf(log.id, log.trajectory, grouping);
    for (const auto& [name, offset_s] : offset_of_group) {
      if (name != group) continue;
      for (double& t : log.ground_truth.t_s) t -= offset_s;
      ++moved;
      break;
    }
  }
  return moved;
}

TrackFitData MakeTrackFitData(const std::vector<AlignedRun>& runs,
                              const std::vector<const GroundTruthTrack*>& ground_truth,
                              ClockGrouping grouping, const TrackResidualOptions& options) {
  if (runs.size() != ground_truth.size()) {
    throw std::invalid_argument("MakeTrackFitData: not one ground truth per run");
  }
  TrackFitData out;
  out.options = options;
  out.estimate_clock_offsets = grouping != ClockGrouping::kNone;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    TrackCheckpoints t = MakeTrackCheckpoints(runs[i], *ground_truth[i], options);
    const std::string group = ClockGroupOf(runs[i].id, runs[i].trajectory, grouping);
    const auto found = std::find(out.clock_groups.begin(), out.clock_groups.end(), group);
    t.clock_group = static_cast<int>(found - out.clock_groups.begin());
    if (found == out.clock_groups.end()) out.clock_groups.push_back(group);
    out.runs.push_back(std::move(t));
  }
  return out;
}

namespace {

// The smoothed ground truth S(t) of the header: a kernel-weighted mean of the samples within
// +-H of t (Nadaraya-Watson) with the triweight kernel w(u) = (1 - u^2)^3, u = (t - t_j) / H,
// whose weight and first two derivatives vanish at |u| = 1, so S is twice continuously
// differentiable in t wherever a sample lies within H (beyond the track's ends it settles on the
// end sample). Headings are averaged unwrapped about the sample nearest t.
template <typename T>
Pose2<T> SmoothedAt(const GroundTruthTrack& track, const T& t, double half_width_s) {
  const std::vector<double>& ts = track.t_s;
  const std::vector<Pose2d>& q = track.world_T_robot;
  const double v = ScalarPart(t);
  const auto first = std::upper_bound(ts.begin(), ts.end(), v - half_width_s);
  const auto last = std::lower_bound(ts.begin(), ts.end(), v + half_width_s);
  if (first >= last) {  // no sample strictly inside the window: the nearest end's sample
    const Pose2d& e = v <= ts.front() ? q.front() : q.back();
    return {T(e.x), T(e.y), T(e.theta)};
  }
  const double reference_theta = q[static_cast<std::size_t>(first - ts.begin())].theta;
  T sum_w(0.0), sum_x(0.0), sum_y(0.0), sum_theta(0.0);
  for (auto it = first; it != last; ++it) {
    const std::size_t j = static_cast<std::size_t>(it - ts.begin());
    const T u = (t - ts[j]) / half_width_s;
    const T one_minus = 1.0 - u * u;
    const T w = one_minus * one_minus * one_minus;
    sum_w += w;
    sum_x += w * q[j].x;
    sum_y += w * q[j].y;
    sum_theta += w * (reference_theta + WrapAngle(q[j].theta - reference_theta));
  }
  return {sum_x / sum_w, sum_y / sum_w, sum_theta / sum_w};
}

// Q(t + dt) = Q(t) + S(t + dt) - S(t) (header): `at` holds Q(t) and S(t) at the checkpoint.
template <typename T>
Pose2<T> ShiftedGroundTruth(const GroundTruthTrack& track, double t_s, const T& dt_s,
                            const Pose2d& q_at_t, const Pose2d& smoothed_at_t,
                            double half_width_s) {
  const Pose2<T> s = SmoothedAt(track, t_s + dt_s, half_width_s);
  return {q_at_t.x + (s.x - smoothed_at_t.x), q_at_t.y + (s.y - smoothed_at_t.y),
          q_at_t.theta + (s.theta - smoothed_at_t.theta)};
}

// a^-1 b
template <typename T>
Pose2<T> Between(const Pose2<T>& a, const Pose2<T>& b) {
  using std::cos;
  using std::sin;
  const T c = cos(a.theta), s = sin(a.theta);
  const T dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, b.theta - a.theta};
}

// sqrt(rho(s) / s) for Huber's rho of scale c (header): 1 in the quadratic zone.
template <typename T>
T HuberFactor(const T& s, double c) {
  using std::sqrt;
  if (ScalarPart(s) <= c * c) return T(1.0);
  return sqrt((2.0 * c * sqrt(s) - c * c) / s);
}

// Jet dimensions: the odometry pose (x, y, theta) and the clock offset.
using ErrorJet = ceres::Jet<double, 4>;

}  // namespace

Pose2d GroundTruthFromStart(const TrackCheckpoints& track, std::size_t k, double dt_s) {
  const GroundTruthTrack& g = *track.ground_truth;
  const double h = track.smoothing_half_width_s;
  const auto shifted = [&](double t) {
    return ShiftedGroundTruth(g, t, dt_s, InterpolateGroundTruth(g, t), SmoothedAt(g, t, h), h);
  };
  return Between(shifted(track.t_start_s), shifted(track.t_s[k]));
}

TrackResidual::TrackResidual(const TrackCheckpoints& track, const RobotModelInterface& model,
                             const ResidualWeights& weights, const TrackResidualOptions& options)
    : track_(track),
      weights_(weights),
      huber_scale_(options.huber_scale),
      run_weight_(1.0 /
                  std::sqrt(static_cast<double>(std::max<std::size_t>(1, track.segments.size())))),
      num_parameters_(model.robot().NumParameters()) {
  for (const Segment& s : track.segments) {
    Segment identity = s;
    identity.ground_truth_start_T_end = Pose2d{0.0, 0.0, 0.0};
    from_start_.push_back(identity);
  }
  const GroundTruthTrack& g = *track.ground_truth;
  const double h = track.smoothing_half_width_s;
  start_ = {InterpolateGroundTruth(g, track.t_start_s), SmoothedAt(g, track.t_start_s, h)};
  for (double t : track.t_s) checkpoints_.push_back({InterpolateGroundTruth(g, t), SmoothedAt(g, t, h)});
  // Unit weights: the inner residual is P_k itself (SegmentError with Q = identity).
  odometry_.reset(model.SegmentCost(*track.run, from_start_, ResidualWeights{}));
  set_num_residuals(3 * static_cast<int>(from_start_.size()));
  mutable_parameter_block_sizes()->push_back(num_parameters_);
  mutable_parameter_block_sizes()->push_back(1);
}

ceres::CostFunction* TrackResidual::Create(const TrackCheckpoints& track,
                                           const RobotModelInterface& model,
                                           const ResidualWeights& weights,
                                           const TrackResidualOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument(error);
  if (track.segments.empty() || track.t_s.size() != track.segments.size()) {
    throw std::invalid_argument("TrackResidual: run " + track.run->id + " has no checkpoints");
  }
  return new TrackResidual(track, model, weights, options);
}

bool TrackResidual::Evaluate(double const* const* parameters, double* residuals,
                             double** jacobians) const {
  const int m = num_residuals();
  const int n = num_parameters_;
  std::vector<double> pose(m);
  std::vector<double> pose_jacobian;  // m x n, row-major: dP/dp
  const bool want_p = jacobians != nullptr && jacobians[0] != nullptr;
  if (want_p) pose_jacobian.assign(static_cast<std::size_t>(m) * n, 0.0);
  double* inner_jacobians[1] = {want_p ? pose_jacobian.data() : nullptr};
  if (!odometry_->Evaluate(parameters, pose.data(), want_p ? inner_jacobians : nullptr)) {
    return false;
  }
  const ErrorJet dt_s = ErrorJet(parameters[1][0], 3);
  const GroundTruthTrack& g = *track_.ground_truth;
  const double h = track_.smoothing_half_width_s;
  const Pose2<ErrorJet> q0 =
      ShiftedGroundTruth(g, track_.t_start_s, dt_s, start_.pose, start_.smoothed, h);
  const double inv_xy = 1.0 / weights_.position_sigma_m;
  const double inv_th = 1.0 / weights_.heading_sigma_rad;
  for (int k = 0; k < m / 3; ++k) {
    const Pose2<ErrorJet> p{ErrorJet(pose[3 * k], 0), ErrorJet(pose[3 * k + 1], 1),
                            ErrorJet(pose[3 * k + 2], 2)};
    const GroundTruthPoint& at_k = checkpoints_[k];
    const Pose2<ErrorJet> q =
        Between(q0, ShiftedGroundTruth(g, track_.t_s[k], dt_s, at_k.pose, at_k.smoothed, h));
    using std::cos;
    using std::sin;
    const ErrorJet cq = cos(q.theta), sq = sin(q.theta);
    const ErrorJet ex = p.x - q.x, ey = p.y - q.y;
    ErrorJet e[3] = {(cq * ex + sq * ey) * inv_xy, (-sq * ex + cq * ey) * inv_xy,
                     WrapAngle(p.theta - q.theta) * inv_th};
    const ErrorJet factor =
        run_weight_ * HuberFactor(e[0] * e[0] + e[1] * e[1] + e[2] * e[2], huber_scale_);
    for (int i = 0; i < 3; ++i) {
      const ErrorJet r = factor * e[i];
      const int row = 3 * k + i;
      residuals[row] = r.a;
      if (jacobians == nullptr) continue;
      if (want_p) {  // dr/dp = dr/dP_k dP_k/dp
        for (int j = 0; j < n; ++j) {
          double sum = 0.0;
          for (int c = 0; c < 3; ++c) sum += r.v[c] * pose_jacobian[(3 * k + c) * n + j];
          jacobians[0][row * n + j] = sum;
        }
      }
      if (jacobians[1] != nullptr) jacobians[1][row] = r.v[3];
    }
  }
  return true;
}

}  // namespace fitcal
