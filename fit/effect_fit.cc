#include "fit/effect_fit.h"

#include <ceres/ceres.h>
#include <ceres/dynamic_autodiff_cost_function.h>

#include <Eigen/QR>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fit/ceres_problem.h"
#include "fit/correlation.h"
#include "fit/last_evaluation_memo.h"
#include "fit/model_fit.h"
#include "odometry/parallel_for.h"

namespace fitcal {

namespace {

using effects::ActiveEffect;
using effects::EffectId;

// Pose errors (replay - ground truth) at the ground-truth samples `indices` of the run, and at
// the window's end. err holds 3 values per index, then 3 for the end.
//
// Start pose (any start, at rest or moving): the replay runs from TrackStartPose, the rest pose
// when the log begins at rest. A log that begins moving has no such pose: there the replayed
// poses P(e) are carried by the rigid transform C that puts the replay through the anchor
// samples G_j (StartAnchorIndices) at the encoder times they show, e_j = t_j - t_start - tau, in
// the least-squares sense (one anchor today):
//   turn = mean_j (G_j.theta - P_j.theta),  C.xy = mean_j (G_j.xy - R(turn) P_j.xy),
//   Q(e) = C * P(e):  Q.theta = P.theta + turn,  Q.xy = C.xy + R(turn) P.xy.
// The odometry itself carries the pose from the anchor back to the window's start, so no
// ground-truth interpolation across a (possibly sparse, 0.2-0.3 s) ground-truth interval enters
// the start, and tau reaches the start through the e_j (differentiated). A world-frame effect
// (FloorSlope) is replayed in S's frame and then turned by `turn`, a second-order error (creep x
// the start's error).
template <typename T>
void TrackPoseErrors(const RobotModelInterface& robot_model, const TrackRun& run, const T* p,
                     const std::vector<ActiveEffect<T>>& active, const std::vector<int>& indices,
                     T* err) {
  const AlignedRun& a = run.aligned;
  const T tau = effects::TotalLatency(active);
  const Pose2d start_pose = TrackStartPose(a, run.contexts, run.track, ScalarPart(tau));
  const Pose2<T> start{T(start_pose.x), T(start_pose.y), T(start_pose.theta)};
  const std::vector<int> anchors = StartAnchorIndices(a, run.contexts, run.track, ScalarPart(tau));
  std::vector<Pose2<T>> anchor_pose(anchors.size(), start);
  std::size_t next_anchor = 0;
  std::size_t next = 0;
  const std::size_t n = indices.size();
  std::vector<Pose2<T>> replayed(n);
  const auto lerp = [](const Pose2<T>& p0, const Pose2<T>& p1, const T& f) {
    return Pose2<T>{p0.x + f * (p1.x - p0.x), p0.y + f * (p1.y - p0.y),
                    p0.theta + f * (p1.theta - p0.theta)};
  };
  // Encoder time (from the window start) that ground-truth sample g shows. Which step a sample
  // falls in is decided on the scalar part alone (the same double as the Jet's), so the Jet is
  // made only for the samples interpolated, not for every step's check.
  const double tau_s = ScalarPart(tau);
  const auto encoder_time_s = [&](int g) { return run.track.t_s[g] - a.t_start_s - tau_s; };
  const auto encoder_time = [&](int g) { return T(run.track.t_s[g] - a.t_start_s) - tau; };
  const auto visit = [&](std::size_t k, const Pose2<T>& before, const Pose2<T>& after) {
    const double t0 = run.contexts[k].t_s;
    const double t1 = t0 + run.contexts[k].dt_s;
    const bool last = k + 1 == run.contexts.size();
    while (next_anchor < anchors.size()) {
      if (encoder_time_s(anchors[next_anchor]) > t1 && !last) break;
      const T e = encoder_time(anchors[next_anchor]);
      anchor_pose[next_anchor++] = lerp(before, after, (e - T(t0)) / T(t1 - t0));
    }
    while (next < n) {
      if (encoder_time_s(indices[next]) > t1 && !last) break;
      const T e = encoder_time(indices[next]);
      replayed[next++] = lerp(before, after, (e - T(t0)) / T(t1 - t0));
    }
  };
  const auto kinematics = robot_model.PrepareKinematics(p);
  const auto step = [&kinematics](const T* values, double dt, T* dx, T* dy, T* dtheta) {
    kinematics->Step(values, dt, dx, dy, dtheta);
  };
  Pose2<T> final_pose =
      effects::ReplayStepsWithEffects(step, active, a.samples, run.contexts, start, visit);
  for (; next < n; ++next) replayed[next] = final_pose;  // only for an empty replay
  const AnchorCarry<T> carried = FitAnchorCarry(run.track, anchors, anchor_pose);
  for (std::size_t j = 0; j < n; ++j) {
    const Pose2<T> pose = carried(replayed[j]);
    const Pose2d& gt = run.track.world_T_robot[indices[j]];
    err[3 * j + 0] = pose.x - T(gt.x);
    err[3 * j + 1] = pose.y - T(gt.y);
    err[3 * j + 2] = WrapAngle(pose.theta - T(gt.theta));
  }
  final_pose = carried(final_pose);
  const Pose2<T> gt_end = InterpolateGroundTruth(run.track, T(a.t_final_s) + tau);
  err[3 * n + 0] = final_pose.x - gt_end.x;
  err[3 * n + 1] = final_pose.y - gt_end.y;
  err[3 * n + 2] = WrapAngle(final_pose.theta - gt_end.theta);
}

// The fit's residual (see the header): parameter block 0 = the model's parameters, block 1 + j =
// effect j.
class EffectTrackResidual {
 public:
  EffectTrackResidual(const RobotModelInterface& robot_model, const TrackRun& run,
                      std::vector<EffectId> ids, const ResidualWeights& w)
      : robot_model_(robot_model),
        run_(run),
        ids_(std::move(ids)),
        inv_xy_(1.0 / w.position_sigma_m),
        inv_theta_(1.0 / w.heading_sigma_rad) {}

  int num_residuals() const { return 3 * static_cast<int>(run_.checkpoints.size()); }

  template <typename T>
  bool operator()(T const* const* params, T* residual) const {
    std::vector<ActiveEffect<T>> active;
    active.reserve(ids_.size());
    for (std::size_t j = 0; j < ids_.size(); ++j) active.push_back({ids_[j], params[1 + j]});
    const std::size_t n = run_.checkpoints.size();
    std::vector<T> err(3 * n + 3);
    TrackPoseErrors(robot_model_, run_, params[0], active, run_.checkpoints, err.data());
    const double norm = 1.0 / std::sqrt(static_cast<double>(n));
    for (std::size_t j = 0; j < n; ++j) {
      residual[3 * j + 0] = err[3 * j + 0] * (inv_xy_ * norm);
      residual[3 * j + 1] = err[3 * j + 1] * (inv_xy_ * norm);
      residual[3 * j + 2] = err[3 * j + 2] * (inv_theta_ * norm);
    }
    return true;
  }

  static ceres::CostFunction* Create(const RobotModelInterface& robot_model, const TrackRun& run,
                                     const std::vector<EffectId>& ids, const ResidualWeights& w) {
    auto* functor = new EffectTrackResidual(robot_model, run, ids, w);
    // The stride is EffectJet's: the model's PrepareKinematics serves exactly that Jet.
    auto* cost = new ceres::DynamicAutoDiffCostFunction<EffectTrackResidual, 4>(functor);
    cost->AddParameterBlock(robot_model.robot().NumParameters());
    for (EffectId id : ids) cost->AddParameterBlock(effects::Info(id).num_parameters);
    cost->SetNumResiduals(functor->num_residuals());
    return cost;
  }

 private:
  const RobotModelInterface& robot_model_;
  const TrackRun& run_;
  std::vector<EffectId> ids_;
  double inv_xy_;
  double inv_theta_;
};

std::vector<ActiveEffect<double>> ActiveOf(const EffectModel& model) {
  std::vector<ActiveEffect<double>> active;
  for (const auto& e : model) active.push_back({e.id, e.value.data()});
  return active;
}

std::vector<EffectId> IdsOf(const EffectModel& model) {
  std::vector<EffectId> ids;
  for (const auto& e : model) ids.push_back(e.id);
  return ids;
}

}  // namespace

std::vector<AlignedRun> AlignedOf(const std::vector<TrackRun>& runs) {
  std::vector<AlignedRun> out;
  out.reserve(runs.size());
  for (const TrackRun& r : runs) out.push_back(r.aligned);
  return out;
}

unsigned WheelChannelMask(const Robot& robot) {
  unsigned mask = 0;
  for (int i = 0; i < robot.NumChannels(); ++i) {
    if (robot.channels[i].kind == ChannelKind::kWheelRate) mask |= 1u << i;
  }
  return mask;
}

bool TrackStartsAtRest(const AlignedRun& run, const std::vector<effects::SampleContext>& contexts,
                       const GroundTruthTrack& track, double latency_s) {
  // Encoder time (from the window start) at which the robot starts moving.
  const auto first_moving = std::find_if(contexts.begin(), contexts.end(),
                                         [](const effects::SampleContext& c) { return c.moving; });
  const double rest_until_s = first_moving != contexts.end() ? first_moving->t_s
                              : contexts.empty()             ? 0.0
                                                 : contexts.back().t_s + contexts.back().dt_s;
  const auto first = std::lower_bound(track.t_s.begin(), track.t_s.end(), run.t_start_s);
  return rest_until_s > 0.0 && first != track.t_s.end() &&
         *first - run.t_start_s - latency_s <= rest_until_s;
}

Pose2d TrackStartPose(const AlignedRun& run, const std::vector<effects::SampleContext>& contexts,
                      const GroundTruthTrack& track, double latency_s) {
  if (TrackStartsAtRest(run, contexts, track, latency_s)) {
    const auto first = std::lower_bound(track.t_s.begin(), track.t_s.end(), run.t_start_s);
    return track.world_T_robot[static_cast<std::size_t>(first - track.t_s.begin())];
  }
  return InterpolateGroundTruth(track, run.t_start_s + latency_s);
}

std::vector<int> StartAnchorIndices(const AlignedRun& run,
                                    const std::vector<effects::SampleContext>& contexts,
                                    const GroundTruthTrack& track, double latency_s) {
  if (TrackStartsAtRest(run, contexts, track, latency_s)) return {};
  // The largest latency the time-offset effect admits (its registry bound).
  const double margin_s = effects::Info(EffectId::kTimeOffset).upper[0];
  const auto first = std::lower_bound(track.t_s.begin(), track.t_s.end(), run.t_start_s + margin_s);
  if (first == track.t_s.end() || *first > run.t_final_s - margin_s) return {};
  return {static_cast<int>(first - track.t_s.begin())};
}

namespace {

// The absolute wheel angles at t_start: the log's start angles advanced by each channel's rate
// over the part of the log before the window.
std::vector<double> WindowStartWheelAngles(const EncoderLog& log, double t_start_s) {
  std::vector<double> angle = log.start_angle_rad;
  if (angle.empty()) return angle;
  for (std::size_t k = 0; k < log.samples.size() && log.t_s[k] < t_start_s; ++k) {
    const double dt = std::min(log.t_s[k + 1], t_start_s) - log.t_s[k];
    for (std::size_t i = 0; i < angle.size(); ++i) angle[i] += log.samples[k].value[i] * dt;
  }
  for (double& a : angle) a = a - 2.0 * M_PI * std::floor(a / (2.0 * M_PI));
  return angle;
}

TrackRun PrepareTrackRun(const RunLog& run, unsigned wheel_mask) {
  TrackRun out;
  out.aligned = AlignRun(run);
  out.track = run.ground_truth;
  out.contexts = effects::MakeSampleContexts(out.aligned.samples, wheel_mask);
  out.start_wheel_angle_rad = WindowStartWheelAngles(run.encoders, out.aligned.t_start_s);
  // Checkpoints keep the largest latency the time-offset effect admits (its registry bound) from
  // the window's ends, so that no admissible latency moves them outside the replay.
  const double margin_s = effects::Info(EffectId::kTimeOffset).upper[0];
  const double lo = out.aligned.t_start_s + margin_s;
  const double hi = out.aligned.t_final_s - margin_s;
  for (std::size_t g = 0; g < out.track.t_s.size(); ++g) {
    if (out.track.t_s[g] >= lo && out.track.t_s[g] <= hi)
      out.checkpoints.push_back(static_cast<int>(g));
  }
  if (out.checkpoints.empty()) {
    // Ground truth of the start and end poses only: nothing along the path to fit a track (or
    // an effect) on - said as what the data lack, since every command that fits tracks meets it.
    const std::string where =
        run.ground_truth_path.empty() ? "run " + run.id : run.ground_truth_path;
    throw std::invalid_argument(where +
                                ": no ground-truth sample between the run's ends (the track "
                                "residuals and effects need poses along the path; ground truth "
                                "of start and end poses only is fitted on final poses by `fit`)");
  }
  return out;
}

}  // namespace

std::vector<TrackRun> PrepareTrackRuns(const std::vector<RunLog>& runs, unsigned wheel_mask) {
  std::vector<TrackRun> out(runs.size());
  ParallelFor(runs.size(), 0,
              [&](std::size_t i) { out[i] = PrepareTrackRun(runs[i], wheel_mask); });
  return out;
}

FinalPoseErrors FinalPoseErrorsOf(const ModelScore& score) {
  FinalPoseErrors e;
  e.cf = score.cf;
  const double n = static_cast<double>(score.runs.size());
  for (const RunScore& r : score.runs) {
    e.mean_position_error_m += std::hypot(r.final_dx_m, r.final_dy_m) / n;
    e.mean_abs_heading_error_rad += std::abs(r.final_dtheta_rad) / n;
    e.per_run_cf.push_back(r.cf);
  }
  return e;
}

ModelScore ScoreModel(const RobotModelInterface& robot_model, const std::vector<double>& p,
                      const EffectModel& model, const std::vector<TrackRun>& runs,
                      const ResidualWeights& weights, int num_threads) {
  ModelScore out;
  out.runs.resize(runs.size());
  const auto active = ActiveOf(model);
  ParallelFor(runs.size(), num_threads, [&](std::size_t i) {
    const TrackRun& run = runs[i];
    const std::size_t n = run.checkpoints.size();
    std::vector<double> err(3 * n + 3);
    TrackPoseErrors(robot_model, run, p.data(), active, run.checkpoints, err.data());
    RunScore& s = out.runs[i];
    double sum_xy = 0.0, sum_th = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      sum_xy += err[3 * j] * err[3 * j] + err[3 * j + 1] * err[3 * j + 1];
      sum_th += err[3 * j + 2] * err[3 * j + 2];
    }
    s.objective = (sum_xy / (weights.position_sigma_m * weights.position_sigma_m) +
                   sum_th / (weights.heading_sigma_rad * weights.heading_sigma_rad)) /
                  static_cast<double>(n);
    s.track_rmse_m = std::sqrt(sum_xy / static_cast<double>(n));
    s.track_rmse_rad = std::sqrt(sum_th / static_cast<double>(n));
    s.final_dx_m = err[3 * n];
    s.final_dy_m = err[3 * n + 1];
    s.final_dtheta_rad = err[3 * n + 2];
    s.cf = std::sqrt(s.final_dx_m * s.final_dx_m + s.final_dy_m * s.final_dy_m +
                     s.final_dtheta_rad * s.final_dtheta_rad);
  });
  for (const RunScore& s : out.runs) {
    out.objective += s.objective;
    out.cf += s.cf;
    out.track_rmse_m += s.track_rmse_m * s.track_rmse_m;
    out.track_rmse_rad += s.track_rmse_rad * s.track_rmse_rad;
  }
  if (!runs.empty()) {
    const double n = static_cast<double>(runs.size());
    out.cf /= n;
    out.track_rmse_m = std::sqrt(out.track_rmse_m / n);
    out.track_rmse_rad = std::sqrt(out.track_rmse_rad / n);
  }
  return out;
}

TrackErrors ComputeTrackErrors(const RobotModelInterface& robot_model, const std::vector<double>& p,
                               const EffectModel& model, const TrackRun& run, bool all_samples) {
  std::vector<int> indices = run.checkpoints;
  if (all_samples) {
    indices.clear();
    for (std::size_t g = 0; g < run.track.t_s.size(); ++g) {
      const double t = run.track.t_s[g];
      if (t >= run.aligned.t_start_s && t <= run.aligned.t_final_s) {
        indices.push_back(static_cast<int>(g));
      }
    }
  }
  // With a latency the window's edge samples may fall outside the replay: keep them inside.
  const auto active = ActiveOf(model);
  const double tau = effects::TotalLatency(active);
  indices.erase(std::remove_if(indices.begin(), indices.end(),
                               [&](int g) {
                                 const double e = run.track.t_s[g] - tau;
                                 return e < run.aligned.t_start_s || e > run.aligned.t_final_s;
                               }),
                indices.end());
  std::vector<double> err(3 * indices.size() + 3);
  TrackPoseErrors(robot_model, run, p.data(), active, indices, err.data());
  TrackErrors out;
  for (std::size_t j = 0; j < indices.size(); ++j) {
    out.t_s.push_back(run.track.t_s[indices[j]]);
    out.ground_truth.push_back(run.track.world_T_robot[indices[j]]);
    out.error.push_back(Pose2d{err[3 * j], err[3 * j + 1], err[3 * j + 2]});
  }
  const std::size_t n = indices.size();
  out.final_error = Pose2d{err[3 * n], err[3 * n + 1], err[3 * n + 2]};
  return out;
}

namespace {

// The registry's box on every effect's parameters, and the held ones at 0; returns how many are
// free.
int BoundEffectParameters(const EffectFitOptions& options, EffectModel* model,
                          ceres::Problem* problem) {
  int count = 0;
  for (auto& e : *model) {
    const auto& info = effects::Info(e.id);
    std::vector<int> held;
    for (const auto& h : options.held_effect_parameters) {
      if (h.id == e.id && h.index < info.num_parameters) held.push_back(h.index);
    }
    count += info.num_parameters - static_cast<int>(held.size());
    for (int k = 0; k < info.num_parameters; ++k) {
      e.value[k] = std::clamp(e.value[k], info.lower[k], info.upper[k]);
      problem->SetParameterLowerBound(e.value.data(), k, info.lower[k]);
      problem->SetParameterUpperBound(e.value.data(), k, info.upper[k]);
    }
    for (int k : held) e.value[k] = 0.0;
    if (static_cast<int>(held.size()) == info.num_parameters) {
      problem->SetParameterBlockConstant(e.value.data());
    } else if (!held.empty()) {
      problem->SetManifold(e.value.data(), new ceres::SubsetManifold(info.num_parameters, held));
    }
  }
  return count;
}

// Finite values, and whether an effect parameter rests on a bound that is not its neutral value.
bool CheckEffectValues(const std::vector<double>& p, EffectFitResult* result) {
  bool finite = std::all_of(p.begin(), p.end(), [](double v) { return std::isfinite(v); });
  for (auto& e : result->effects) {
    const auto& info = effects::Info(e.id);
    for (int k = 0; k < info.num_parameters; ++k) {
      finite = finite && std::isfinite(e.value[k]);
      const Interval box{info.lower[k], info.upper[k]};
      // A one-sided bound at the neutral value (backlash >= 0) is a legitimate "no effect".
      const bool neutral_bound = box.lo == 0.0 && e.value[k] <= 1e-6 * box.Width();
      if (!neutral_bound && AtBound(e.value[k], box)) result->any_at_bound = true;
    }
  }
  return finite;
}

}  // namespace

EffectFitResult FitEffectModel(const std::vector<TrackRun>& training,
                               const RobotModelInterface& robot_model,
                               const std::vector<double>& start_p, const EffectModel& start,
                               const EffectFitOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("EffectFitOptions: " + error);
  if (training.empty()) throw std::invalid_argument("FitEffectModel: no training runs");
  const Robot& robot = robot_model.robot();
  if (static_cast<int>(start_p.size()) != robot.NumParameters()) {
    throw std::invalid_argument("FitEffectModel: start has the wrong number of parameters");
  }
  EffectFitResult result;
  result.parameters = start_p;
  result.effects = start;
  double* p = result.parameters.data();
  const std::vector<EffectId> ids = IdsOf(start);

  ceres::Problem problem(ProblemOptionsOnSharedContext());
  std::vector<double*> blocks = {p};
  for (auto& e : result.effects) blocks.push_back(e.value.data());
  std::vector<ceres::ResidualBlockId> runs;
  // Each run's block behind a memo: Ceres' bounded line search evaluates a step's end with
  // Jacobians and the successful step evaluates it again (fit/last_evaluation_memo.h).
  for (const TrackRun& run : training) {
    runs.push_back(problem.AddResidualBlock(
        new LastEvaluationMemo(
            EffectTrackResidual::Create(robot_model, run, ids, options.weights)),
        MakeLoss(options), blocks));
  }
  BoundModelBlock(robot, HoldAtNominal(robot, p), p, &problem);
  const int num_effect_parameters = BoundEffectParameters(options, &result.effects, &problem);

  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptionsFor(options), &problem, &summary);
  result.termination = ceres::TerminationTypeToString(summary.termination_type);
  result.message = summary.message;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.final_cost = summary.final_cost;
  const bool finite = CheckEffectValues(result.parameters, &result);
  result.usable = finite && (summary.termination_type == ceres::CONVERGENCE ||
                             summary.termination_type == ceres::NO_CONVERGENCE);

  const int dof = 3 * static_cast<int>(training.size()) - robot.NumFree() - num_effect_parameters;
  if (!options.compute_covariance || !result.usable || dof <= 0) return result;
  // s^2 per run-residual (header). A pseudo-inverse: an effect aliased with the model gets its
  // (large) sigma rather than no covariance for the whole fit; SeparableFraction says which
  // candidates the runs cannot tell apart.
  const std::vector<Eigen::MatrixXd> covariance =
      ScaledCovariance(&problem, {blocks.begin(), blocks.end()}, SumOfSquares(&problem, runs) / dof,
                       /*pseudo_inverse=*/true, options.num_threads);
  if (covariance.empty()) return result;
  result.sigma = SigmasOf(covariance[0]);
  result.correlation = CorrelationOf(covariance[0]);
  for (std::size_t j = 0; j < result.effects.size(); ++j) {
    const std::vector<double> sigma = SigmasOf(covariance[1 + j]);
    std::copy(sigma.begin(), sigma.end(), result.effects[j].sigma.begin());
  }
  result.has_covariance = true;
  return result;
}

double SeparableFraction(const std::vector<TrackRun>& training,
                         const RobotModelInterface& robot_model, const std::vector<double>& p,
                         const EffectModel& model, EffectId candidate,
                         const ResidualWeights& weights, double* unexplained_norm,
                         double* linearized_size, double* linearized_residual_ss) {
  EffectModel with = model;
  effects::EffectValue c;
  c.id = candidate;
  with.push_back(c);
  const std::vector<EffectId> ids = IdsOf(with);
  const int m_c = effects::Info(candidate).num_parameters;
  // The runs' residuals stacked, their Jacobian's columns in block order (model, then effects).
  std::vector<double> p_at = p;
  std::vector<double*> blocks = {p_at.data()};
  for (auto& e : with) blocks.push_back(e.value.data());
  ceres::Problem problem(ProblemOptionsOnSharedContext());
  for (const TrackRun& run : training) {
    problem.AddResidualBlock(EffectTrackResidual::Create(robot_model, run, ids, weights), nullptr,
                             blocks);
  }
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  ceres::CRSMatrix crs;
  std::vector<double> residuals;
  problem.Evaluate(evaluate, nullptr, linearized_size != nullptr ? &residuals : nullptr, nullptr,
                   &crs);
  const Eigen::MatrixXd jac = Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>>(
                                  crs.num_rows, crs.num_cols, static_cast<int>(crs.values.size()),
                                  crs.rows.data(), crs.cols.data(), crs.values.data())
                                  .toDense();
  const int cols = crs.num_cols;
  const Eigen::MatrixXd others = jac.leftCols(cols - m_c);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(others);
  double fraction = 1.0;
  double smallest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < m_c; ++k) {
    const Eigen::VectorXd column = jac.col(cols - m_c + k);
    const double norm = column.norm();
    const double left = norm > 0.0 ? (column - others * qr.solve(column)).norm() : 0.0;
    smallest = std::min(smallest, left);
    fraction = std::min(fraction, norm > 0.0 ? left / norm : 0.0);
  }
  if (unexplained_norm != nullptr) *unexplained_norm = smallest;
  if (linearized_size != nullptr) {
    const Eigen::Map<const Eigen::VectorXd> r(residuals.data(),
                                              static_cast<Eigen::Index>(residuals.size()));
    const Eigen::VectorXd step = jac.colPivHouseholderQr().solve(-r);
    *linearized_size = step.tail(m_c).cwiseAbs().maxCoeff();
    if (linearized_residual_ss != nullptr) *linearized_residual_ss = (r + jac * step).squaredNorm();
  }
  return fraction;
}

}  // namespace fitcal
