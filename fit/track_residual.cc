#include "fit/track_residual.h"

#include <ceres/jet.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "fit/segment_cost.h"
#include "odometry/invalid.h"
#include "odometry/pose_between.h"

namespace fitcal {

bool TrackResidualOptions::IsValid(std::string* error) const {
  if (!(checkpoint_spacing_m > 0.0) || !(huber_scale > 0.0))
    return Invalid(error, "track: checkpoint spacing and loss scale must be positive");
  return true;
}

TrackCheckpoints MakeTrackCheckpoints(const AlignedRun& run, const GroundTruthTrack& ground_truth,
                                      const TrackResidualOptions& options) {
  TrackCheckpoints out;
  out.run = &run;
  out.ground_truth = &ground_truth;
  out.t_start_s = run.t_start_s;
  out.segments = MakeCheckpointsFromStart(run, ground_truth, options.checkpoint_spacing_m);
  double t = run.t_start_s;
  std::size_t done = 0;
  for (const Segment& s : out.segments) {
    for (; done < s.end; ++done) t += run.samples[done].dt_s;
    out.t_s.push_back(t);
  }
  return out;
}

const char* ToString(TrackHeading heading) {
  return heading == TrackHeading::kIncrements ? "increments" : "from-start";
}

bool ParseTrackHeading(const std::string& text, TrackHeading* out) {
  for (TrackHeading h : {TrackHeading::kFromStart, TrackHeading::kIncrements}) {
    if (text == ToString(h)) {
      *out = h;
      return true;
    }
  }
  return false;
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

RunGroups GroupRuns(const std::vector<AlignedRun>& runs, ClockGrouping grouping) {
  RunGroups out;
  for (const AlignedRun& run : runs) {
    const std::string group = ClockGroupOf(run.id, run.trajectory, grouping);
    const auto found = std::find(out.names.begin(), out.names.end(), group);
    out.of_run.push_back(static_cast<int>(found - out.names.begin()));
    if (found == out.names.end()) out.names.push_back(group);
  }
  return out;
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
  RunGroups groups = GroupRuns(runs, grouping);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    TrackCheckpoints t = MakeTrackCheckpoints(runs[i], *ground_truth[i], options);
    t.clock_group = groups.of_run[i];
    out.runs.push_back(std::move(t));
  }
  out.clock_groups = std::move(groups.names);
  return out;
}

namespace {

// sqrt(rho(s) / s) for Huber's rho of scale c (header): 1 in the quadratic zone.
template <typename T>
T HuberFactor(const T& s, double c) {
  using std::sqrt;
  if (ScalarPart(s) <= c * c) return T(1.0);
  return sqrt((2.0 * c * sqrt(s) - c * c) / s);
}

}  // namespace

Pose2d GroundTruthFromStart(const TrackCheckpoints& track, std::size_t k, double dt_s) {
  return Between(InterpolateGroundTruth(*track.ground_truth, track.t_start_s + dt_s),
                 InterpolateGroundTruth(*track.ground_truth, track.t_s[k] + dt_s));
}

namespace {

// Whether `kept` holds `num_poses` poses for bitwise the same parameters `p` (the same doubles,
// not merely equal ones, as LastEvaluationMemo).
template <typename Kept>
bool KeptFor(const std::optional<Kept>& kept, const double* p, int num_parameters,
             int num_poses) {
  return kept && kept->pose.size() == static_cast<std::size_t>(num_poses) &&
         kept->p.size() == static_cast<std::size_t>(num_parameters) &&
         std::memcmp(kept->p.data(), p, num_parameters * sizeof(double)) == 0;
}

}  // namespace

bool OdometryMemo::Recall(const double* p, int num_parameters, double* pose, int num_poses,
                          double* jacobian, bool values_alike) {
  const std::optional<Kept>* kept = jacobian != nullptr ? &with_jacobian_ : &values_;
  if (!KeptFor(*kept, p, num_parameters, num_poses)) {
    if (jacobian != nullptr || !values_alike) return false;
    kept = &with_jacobian_;
    if (!KeptFor(*kept, p, num_parameters, num_poses)) return false;
  }
  ++recalled_;
  std::copy((*kept)->pose.begin(), (*kept)->pose.end(), pose);
  if (jacobian != nullptr) std::copy((*kept)->jacobian.begin(), (*kept)->jacobian.end(), jacobian);
  return true;
}

void OdometryMemo::Keep(const double* p, int num_parameters, const double* pose, int num_poses,
                        const double* jacobian) {
  std::optional<Kept>& kept = jacobian != nullptr ? with_jacobian_ : values_;
  if (!kept) kept.emplace();
  kept->p.assign(p, p + num_parameters);
  kept->pose.assign(pose, pose + num_poses);
  if (jacobian != nullptr) {
    kept->jacobian.assign(jacobian,
                          jacobian + static_cast<std::size_t>(num_poses) * num_parameters);
  }
}

TrackResidual::TrackResidual(const TrackCheckpoints& track, const RobotModelInterface& model,
                             const ResidualWeights& weights, const TrackResidualOptions& options,
                             OdometryMemo* memo)
    : track_(track),
      weights_(weights),
      huber_scale_(options.huber_scale),
      heading_(options.heading),
      run_weight_(1.0 /
                  std::sqrt(static_cast<double>(std::max<std::size_t>(1, track.segments.size())))),
      num_parameters_(model.robot().NumParameters()),
      values_alike_(model.SegmentResidualsAlikeWithJacobians()),
      memo_(memo) {
  for (const Segment& s : track.segments) {
    Segment identity = s;
    identity.ground_truth_start_T_end = Pose2d{0.0, 0.0, 0.0};
    from_start_.push_back(identity);
  }
  // Unit weights: the inner residual is P_k itself (SegmentError with Q = identity).
  odometry_.reset(model.SegmentCost(*track.run, from_start_, ResidualWeights{}));
  set_num_residuals(3 * static_cast<int>(from_start_.size()));
  mutable_parameter_block_sizes()->push_back(num_parameters_);
  mutable_parameter_block_sizes()->push_back(1);
}

ceres::CostFunction* TrackResidual::Create(const TrackCheckpoints& track,
                                           const RobotModelInterface& model,
                                           const ResidualWeights& weights,
                                           const TrackResidualOptions& options,
                                           OdometryMemo* memo) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument(error);
  if (track.segments.empty() || track.t_s.size() != track.segments.size()) {
    throw std::invalid_argument("TrackResidual: run " + track.run->id + " has no checkpoints");
  }
  return new TrackResidual(track, model, weights, options, memo);
}

namespace {

// A variable of the checkpoint residual: a Jet with derivative 1 in dimension `dimension`, or
// the plain value on double.
template <typename T>
T Variable(double value, int dimension) {
  if constexpr (std::is_same_v<T, double>) {
    return value;
  } else {
    return T(value, dimension);
  }
}

}  // namespace

// The ground truth's pose at every checkpoint from the run's start, the ground truth read at
// t + dt_s (the clock offset is Jet dimension 3): the start's rotation is formed once and each
// checkpoint's pose once, where one Between per checkpoint, and another for the checkpoint before
// it (kIncrements), formed them again - the same operations on the same numbers.
template <typename T>
std::vector<Pose2<T>> TrackResidual::GroundTruthFromStartAt(double dt_s) const {
  using std::cos;
  using std::sin;
  const GroundTruthTrack& ground_truth = *track_.ground_truth;
  std::size_t bracket = 0;  // the checkpoints follow the start in time
  const Pose2<T> q0 =
      InterpolateGroundTruth(ground_truth, Variable<T>(track_.t_start_s + dt_s, 3), &bracket);
  const T c = cos(q0.theta), s = sin(q0.theta);
  std::vector<Pose2<T>> out;
  out.reserve(from_start_.size());
  for (std::size_t k = 0; k < from_start_.size(); ++k) {
    const Pose2<T> q =
        InterpolateGroundTruth(ground_truth, Variable<T>(track_.t_s[k] + dt_s, 3), &bracket);
    out.push_back(BetweenRotated(q0, c, s, q));
  }
  return out;
}

// r_k of the header for the odometry poses `pose` (3 per checkpoint) and the ground truth's from
// GroundTruthFromStartAt, as Jets in (P_k, dt), or its value on double (the Jets' value parts:
// the same operations on the same numbers).
template <typename T>
std::array<T, 3> TrackResidual::CheckpointResidual(
    const std::vector<double>& pose, int k, const std::vector<Pose2<T>>& ground_truth) const {
  using std::cos;
  using std::sin;
  const Pose2<T> p{Variable<T>(pose[3 * k], 0), Variable<T>(pose[3 * k + 1], 1),
                   Variable<T>(pose[3 * k + 2], 2)};
  const Pose2<T>& q = ground_truth[k];
  const double inv_xy = 1.0 / weights_.position_sigma_m;
  const double inv_th = 1.0 / weights_.heading_sigma_rad;
  const T cq = cos(q.theta), sq = sin(q.theta);
  const T ex = p.x - q.x, ey = p.y - q.y;
  T heading_error = p.theta - q.theta;
  if (heading_ == TrackHeading::kIncrements && k > 0) {
    // Minus the same error at checkpoint k - 1: the odometry's heading there (Jet dimension 4)
    // against the ground truth's.
    const T p_before = Variable<T>(pose[3 * (k - 1) + 2], 4);
    heading_error = heading_error - (p_before - ground_truth[k - 1].theta);
  }
  const T e[3] = {(cq * ex + sq * ey) * inv_xy, (-sq * ex + cq * ey) * inv_xy,
                  WrapAngle(heading_error) * inv_th};
  const T factor =
      run_weight_ * HuberFactor(e[0] * e[0] + e[1] * e[1] + e[2] * e[2], huber_scale_);
  return {factor * e[0], factor * e[1], factor * e[2]};
}

bool TrackResidual::EvaluateOdometry(const double* p, double* pose, double* jacobian) const {
  const int m = num_residuals();
  if (memo_ != nullptr && memo_->Recall(p, num_parameters_, pose, m, jacobian, values_alike_)) {
    return true;
  }
  const double* parameters[] = {p};
  double* inner_jacobians[1] = {jacobian};
  if (!odometry_->Evaluate(parameters, pose, jacobian != nullptr ? inner_jacobians : nullptr)) {
    return false;
  }
  if (memo_ != nullptr) memo_->Keep(p, num_parameters_, pose, m, jacobian);
  return true;
}

std::vector<double> TrackResidual::OdometryFromStart(const double* p) const {
  std::vector<double> pose(num_residuals());
  if (!EvaluateOdometry(p, pose.data(), nullptr)) pose.assign(pose.size(), HUGE_VAL);
  return pose;
}

double TrackResidual::SquaredNormAt(const std::vector<double>& pose, double dt_s) const {
  const std::vector<Pose2d> ground_truth = GroundTruthFromStartAt<double>(dt_s);
  double sum = 0.0;
  for (int k = 0; k < num_residuals() / 3; ++k) {
    for (const double r : CheckpointResidual(pose, k, ground_truth)) sum += r * r;
  }
  return sum;
}

bool TrackResidual::Evaluate(double const* const* parameters, double* residuals,
                             double** jacobians) const {
  const int m = num_residuals();
  const int n = num_parameters_;
  std::vector<double> pose(m);
  std::vector<double> pose_jacobian;  // m x n, row-major: dP/dp
  const bool want_p = jacobians != nullptr && jacobians[0] != nullptr;
  if (want_p) pose_jacobian.assign(static_cast<std::size_t>(m) * n, 0.0);
  if (!EvaluateOdometry(parameters[0], pose.data(), want_p ? pose_jacobian.data() : nullptr)) {
    return false;
  }
  const double dt_s = parameters[1][0];
  const std::vector<Pose2<ErrorJet>> ground_truth = GroundTruthFromStartAt<ErrorJet>(dt_s);
  for (int k = 0; k < m / 3; ++k) {
    const std::array<ErrorJet, 3> rk = CheckpointResidual(pose, k, ground_truth);
    for (int i = 0; i < 3; ++i) {
      const ErrorJet& r = rk[i];
      const int row = 3 * k + i;
      residuals[row] = r.a;
      if (jacobians == nullptr) continue;
      if (want_p) {  // dr/dp = dr/dP_k dP_k/dp (+ dr/dtheta_Pk-1 dtheta_Pk-1/dp)
        for (int j = 0; j < n; ++j) {
          double sum = 0.0;
          for (int c = 0; c < 3; ++c) sum += r.v[c] * pose_jacobian[(3 * k + c) * n + j];
          if (k > 0) sum += r.v[4] * pose_jacobian[(3 * (k - 1) + 2) * n + j];
          jacobians[0][row * n + j] = sum;
        }
      }
      if (jacobians[1] != nullptr) jacobians[1][row] = r.v[3];
    }
  }
  return true;
}

}  // namespace fitcal
