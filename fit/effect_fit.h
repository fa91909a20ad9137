#pragma once
// A robot model's parameters (models/model_interface.h) plus candidate effects
// (odometry/effects.h), fitted to the whole ground-truth track of each run. The final pose alone
// cannot see every effect (a clock latency vanishes when runs end at rest), so the residual of a
// run is the pose error at every ground-truth sample of its window ("checkpoints"):
//
//   r_j = [ (x(t_j - tau) - x_gt_j) / sigma_xy, (y(...) - y_gt_j) / sigma_xy,
//           wrap(theta(...) - theta_gt_j) / sigma_theta ] / sqrt(n_checkpoints)
//
// with the replay of odometry/effects.h (the model's body steps + effect stages) started
// at the rest pose (TrackStartsAtRest) or moved rigidly through the anchor ground-truth sample at
// the encoder time it shows (StartAnchorIndices);
// tau is the time-offset effect's latency (0 without it). The
// 1/sqrt(n) weight makes a run's squared residual its mean squared track error, so every run
// counts once, whatever its length. One functor serves Ceres (dynamic autodiff) and the
// double-valued scoring.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fit/final_pose_errors.h"
#include "fit/solver_options.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/effects.h"
#include "odometry/run_log.h"

namespace fitcal {

// A run prepared for track residuals.
struct TrackRun {
  AlignedRun aligned;
  GroundTruthTrack track;                        // the whole ground truth (interpolation)
  std::vector<effects::SampleContext> contexts;  // one per aligned sample
  std::vector<int> checkpoints;                  // indices into track
  // Each channel's absolute wheel angle at the window's start (rad, in [0, 2 pi); NaN where
  // unknown), from EncoderLog::start_angle_rad; empty when the log carries none.
  std::vector<double> start_wheel_angle_rad;
};

// Whether the window's first ground-truth sample shows the robot still at rest (every wheel
// below effects::kMovingRateRadS until the encoder time it shows; with a positive latency it shows
// a time just before the window, when a run that starts at rest was at rest too). `contexts` are
// the run's (effects::MakeSampleContexts); their `moving` flags say where the rest ends.
bool TrackStartsAtRest(const AlignedRun& run, const std::vector<effects::SampleContext>& contexts,
                       const GroundTruthTrack& track, double latency_s);

// The pose the replay of a track starts from, given a ground-truth latency (the ground-truth
// sample stamped t shows encoder time t - latency): that first sample when TrackStartsAtRest,
// else the ground truth interpolated at t_start + latency - only a first guess then: the track
// residual carries the replay through the anchor (StartAnchorIndices), since interpolating a
// ground truth sampled every 0.2-0.3 s across the start of the motion blends the rest pose with
// one a ground-truth period into the motion (a 0.06 s latency was read as 0.083 s that way).
Pose2d TrackStartPose(const AlignedRun& run, const std::vector<effects::SampleContext>& contexts,
                      const GroundTruthTrack& track, double latency_s);

// The ground-truth samples that anchor the replay of a log that does not begin at rest: the first
// sample at least the largest admissible latency (the time-offset effect's bound, 0.3 s) after the
// window's start and that far before its end, so that the encoder time it shows,
// t - t_start - tau, lies inside the replay for every admissible tau. The replay is moved rigidly
// to pass through it at that encoder time: the start pose is the anchor carried back by the
// model's own odometry, and tau reaches it (differentiably) through that encoder time. One
// sample: averaging a span of them would lower the start's ground-truth noise but absorb what
// the track shows in that span (a backlash at the start of the motion). Empty when the log
// begins at rest (the rest pose is the start) or the window holds no such sample.
std::vector<int> StartAnchorIndices(const AlignedRun& run,
                                    const std::vector<effects::SampleContext>& contexts,
                                    const GroundTruthTrack& track, double latency_s);

// The rigid transform C that puts replayed poses P_j through the anchor ground-truth samples G_j
// (StartAnchorIndices) in the least-squares sense:
//   turn = mean_j (G_j.theta - P_j.theta),  C.xy = mean_j (G_j.xy - R(turn) P_j.xy),
//   C * P:  theta + turn,  C.xy + R(turn) P.xy.
// The identity without anchors. T is double or a Jet (the effect fit differentiates through it).
template <typename T>
struct AnchorCarry {
  bool identity = true;
  T turn = T(0.0), cos_turn = T(1.0), sin_turn = T(0.0), x = T(0.0), y = T(0.0);
  Pose2<T> operator()(const Pose2<T>& q) const {
    if (identity) return q;
    return {x + cos_turn * q.x - sin_turn * q.y, y + sin_turn * q.x + cos_turn * q.y,
            q.theta + turn};
  }
};

template <typename T>
AnchorCarry<T> FitAnchorCarry(const GroundTruthTrack& track, const std::vector<int>& anchors,
                              const std::vector<Pose2<T>>& anchor_pose) {
  using std::cos;
  using std::sin;
  AnchorCarry<T> carry;
  if (anchors.empty()) return carry;
  carry.identity = false;
  const double m = static_cast<double>(anchors.size());
  // Each difference taken near the first one: headings may wrap between the two tracks.
  const T d0 = T(track.world_T_robot[anchors[0]].theta) - anchor_pose[0].theta;
  for (std::size_t j = 0; j < anchors.size(); ++j) {
    const T d = T(track.world_T_robot[anchors[j]].theta) - anchor_pose[j].theta;
    carry.turn += (d0 + WrapAngle(d - d0)) / m;
  }
  carry.cos_turn = cos(carry.turn);
  carry.sin_turn = sin(carry.turn);
  for (std::size_t j = 0; j < anchors.size(); ++j) {
    const Pose2d& g = track.world_T_robot[anchors[j]];
    carry.x +=
        (T(g.x) - (carry.cos_turn * anchor_pose[j].x - carry.sin_turn * anchor_pose[j].y)) / m;
    carry.y +=
        (T(g.y) - (carry.sin_turn * anchor_pose[j].x + carry.cos_turn * anchor_pose[j].y)) / m;
  }
  return carry;
}

// wheel_mask: bit i set when channel i is a wheel rate (WheelChannelMask); the default, every
// channel, suits a robot whose channels are all wheels (omni3's three).
std::vector<TrackRun> PrepareTrackRuns(const std::vector<RunLog>& runs, unsigned wheel_mask = ~0u);
// Bit i set when the robot's channel i is a wheel rate (effects::SampleContext::wheel_mask).
unsigned WheelChannelMask(const Robot& robot);
// The split of track runs (fit/run_split.h) reads each run's aligned part.
inline const AlignedRun& AlignedOf(const TrackRun& run) { return run.aligned; }
// Copies of the runs' aligned parts, for the fits and scores of aligned runs.
std::vector<AlignedRun> AlignedOf(const std::vector<TrackRun>& runs);

using EffectModel = std::vector<effects::EffectValue>;

// Scores of one run under a model (double evaluation of the functor below).
struct RunScore {
  double objective = 0.0;  // mean squared weighted track error (the fit's per-run cost)
  double cf = 0.0;         // Palacin Eq. 14 at the window's end
  double final_dx_m = 0.0, final_dy_m = 0.0, final_dtheta_rad = 0.0;  // world frame
  double track_rmse_m = 0.0;    // position RMSE over the checkpoints
  double track_rmse_rad = 0.0;  // heading RMSE over the checkpoints
};

struct ModelScore {
  std::vector<RunScore> runs;
  double objective = 0.0;     // sum over runs
  double cf = 0.0;            // mean over runs
  double track_rmse_m = 0.0;  // sqrt(mean over runs of track_rmse_m^2)
  double track_rmse_rad = 0.0;
};

// The score's final poses as the final-pose fit reports them: CF, mean position and mean
// |heading| error over the runs (the effect replay's pose at each window's end).
FinalPoseErrors FinalPoseErrorsOf(const ModelScore& score);

ModelScore ScoreModel(const RobotModelInterface& robot_model, const std::vector<double>& p,
                      const EffectModel& model, const std::vector<TrackRun>& runs,
                      const ResidualWeights& weights = {}, int num_threads = 0);

// Pose error of the replay at every checkpoint of a run (world frame, replay minus ground
// truth), with the checkpoint times and ground-truth poses; for residual analysis.
struct TrackErrors {
  std::vector<double> t_s;  // ground-truth stamps
  std::vector<Pose2d> ground_truth;
  std::vector<Pose2d> error;  // x, y in m (world), theta wrapped (rad)
  Pose2d final_error;         // at the window's end, as RunScore's final_d* (Eq. 14's residual)
};
TrackErrors ComputeTrackErrors(const RobotModelInterface& robot_model, const std::vector<double>& p,
                               const EffectModel& model, const TrackRun& run, bool all_samples);

// The shared Ceres settings (fit/solver_options.h) with the tracing's iteration limit and
// tolerances: it fits every candidate effect and judges each fit on held-out runs, so a fit still
// creeping after 50 iterations is scored there rather than polished.
struct EffectFitOptions : CeresFitOptions {
  EffectFitOptions() {
    max_num_iterations = 50;
    function_tolerance = 1e-10;
    parameter_tolerance = 1e-10;
  }
  // Effect parameters held at 0 (neutral): those the robot's motion cannot excite (diagnose's
  // LateralOnlyParameters).
  struct HeldEffectParameter {
    effects::EffectId id;
    int index;
  };
  std::vector<HeldEffectParameter> held_effect_parameters;
};

struct EffectFitResult {
  // Finite parameters after CONVERGENCE or NO_CONVERGENCE (iteration limit: the tracing judges
  // every fit on held-out runs, so a fit that was still creeping is scored, not trusted blindly).
  bool usable = false;
  std::string termination;
  std::string message;
  int iterations = 0;
  double final_cost = 0.0;         // 0.5 * sum of per-run objectives (under the options' loss)
  std::vector<double> parameters;  // the model's (robot().parameters order)
  std::vector<double> sigma;       // one sigma of each (when has_covariance; 0 when held)
  Eigen::MatrixXd correlation;     // of the model's parameters, with the effects in the fit
  EffectModel effects;             // fitted values and sigmas
  bool has_covariance = false;
  bool any_at_bound = false;
};

// Fits the model's parameters (started at start_p, bounded by the robot's box, held parameters
// at their nominal) and the effects' parameters (started at the values in `start`, bounded by
// the registry) to the training runs.
// Each run's residual block carries the options' loss (MakeLoss), as the final-pose fit's do.
// Covariance: Ceres' covariance scaled by s^2 = sum of run objectives (without the loss) /
// (3 N_runs - k), i.e. each run counts as three independent residuals (a run's checkpoints are
// correlated through the drift, so counting them all would understate the uncertainty).
EffectFitResult FitEffectModel(const std::vector<TrackRun>& training,
                               const RobotModelInterface& robot_model,
                               const std::vector<double>& start_p, const EffectModel& start,
                               const EffectFitOptions& options = {});

// How much of a candidate's influence on the training residuals lies outside what the model's
// parameters (and the effects already in `model`) can produce: |(I - P) J_c| / |J_c| for the
// candidate's Jacobian column J_c (the smallest over its parameters) at the given solution, P the
// projection on the other columns. 0: the data cannot tell the candidate from the others.
// The fraction says nothing of size: an effect with almost no influence can still be
// "separable"; *unexplained_norm (optional) gets |(I - P) J_c| itself, so that
// sigma_c ~ s / |(I - P) J_c| (s the residual RMS) predicts how well the runs could determine the
// candidate before fitting it. *linearized_size (optional) gets the size the residual itself
// asks of the candidate: the largest |delta_c| of one Gauss-Newton step of every column from the
// given solution (min |r + J delta|), so an effect larger than the registry's realistic
// magnitude is seen as such before it is fitted; *linearized_residual_ss (optional, with
// linearized_size) gets |r + J delta|^2 of that step, the residual's sum of squares with the
// candidate in the model, from which its sigma is predicted (diagnose.h).
double SeparableFraction(const std::vector<TrackRun>& training,
                         const RobotModelInterface& robot_model, const std::vector<double>& p,
                         const EffectModel& model, effects::EffectId candidate,
                         const ResidualWeights& weights = {}, double* unexplained_norm = nullptr,
                         double* linearized_size = nullptr,
                         double* linearized_residual_ss = nullptr);

}  // namespace fitcal
