#pragma once
// Trajectory error metrics of one run, Palacin et al. 2022 Sec. 2.5 (Eq. 8-13), and the summary of
// many runs that the paper prints as Table 6.
//
// The odometry (Eq. 4, replayed with the given parameters from the run's start pose) is compared
// with the ground truth at the ground-truth times p = 1..m that fall inside the run's window
// [t_start, t_final] (aligned_run.h):
//   distance_error(p) = sqrt((xgt(p) - x(p))^2 + (ygt(p) - y(p))^2)            Eq. 8
//   angle_error(p)    = |wrap(thetagt(p) - theta(p))|                            Eq. 9
//   max of each over p                                                           Eq. 10, 11
//   RMSE of each over p                                                          Eq. 12, 13
// The odometry pose "at" a ground-truth time is, by default, the odometry sample nearest in time
// (the paper's Sec. 2.5: the odometry is sub-sampled at the ground-truth times); linear
// interpolation between the two bracketing encoder times is the alternative. The final errors are
// those of Eq. 14 (replay to t_final against the ground truth interpolated at t_final), so the
// per-run CF here equals EvaluateFinalPoseErrors' (fit/final_pose_errors.h).

#include <cstddef>
#include <string>
#include <vector>

#include "fit/final_pose_errors.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/effects.h"
#include "odometry/run_log.h"

namespace fitcal {

enum class OdometrySampling {
  kNearestTime,          // default: the encoder pose nearest in time (the paper's sub-sampling)
  kLinearInterpolation,  // between the two encoder poses around the ground-truth time
};

const char* ToString(OdometrySampling sampling);

// One run replayed with one parameter set.
struct TrajectoryErrors {
  std::vector<double> t_s;               // ground-truth times used (inside the window)
  std::vector<Pose2d> ground_truth;      // world_T_robot from the ground truth at t_s
  std::vector<Pose2d> odometry;          // odometry sub-sampled at t_s
  std::vector<double> distance_error_m;  // Eq. 8
  std::vector<double> angle_error_rad;   // Eq. 9, in [0, pi]
  double rms_distance_m = 0.0;           // Eq. 12
  double rms_angle_rad = 0.0;            // Eq. 13
  double max_distance_m = 0.0;           // Eq. 10
  double max_angle_rad = 0.0;            // Eq. 11
  Pose2d final_odometry;                 // replayed pose at t_final
  Pose2d final_ground_truth;             // ground truth at t_final
  double final_distance_m = 0.0;         // |final position error|
  double final_angle_rad = 0.0;          // |wrap(final heading error)|
  double cf = 0.0;                       // Eq. 14 of this run (m and rad)
};

// What replaying a run against its ground truth takes from the run and the track alone, whatever
// the parameters and effects: the encoder time of every replayed pose and the track's samples
// inside the run's window. Made once per run where many parameter sets are scored on it
// (everyday_driving.h: EverydayDrivingTruth).
struct RunTimeLine {
  RunTimeLine(const AlignedRun& run, const GroundTruthTrack& track);
  std::vector<double> encoder_times;  // [0] = t_start_s, [k + 1] after sample k
  std::size_t first = 0, end = 0;     // track samples first .. end - 1 lie in [t_start, t_final]
};

// Any model through the seam (models/model_interface.h), replayed with its own kinematics at
// parameters p (robot().parameters order). `track` is the run's ground truth
// (RunLog::ground_truth); `run` its AlignRun(); `time_line` theirs, when made once for many
// calls (the overload below makes it). Throws std::invalid_argument if no ground-truth sample
// lies inside the window.
// With effects (odometry/effects.h, as a calibrated robot YAML carries them after `fitcal
// diagnose`) the semantics are the effect fit's (fit/effect_fit.h): the replay applies every
// effect, and a ground-truth latency tau makes the ground-truth sample stamped t show the odometry
// at encoder time t - tau (the replay is carried through the anchor samples of
// StartAnchorIndices, the final pose is compared with the ground truth at t_final + tau).
TrajectoryErrors EvaluateTrajectory(const RobotModelInterface& model, const AlignedRun& run,
                                    const GroundTruthTrack& track, const RunTimeLine& time_line,
                                    const std::vector<double>& p,
                                    const std::vector<effects::EffectValue>& effects,
                                    OdometrySampling sampling = OdometrySampling::kNearestTime);
TrajectoryErrors EvaluateTrajectory(const RobotModelInterface& model, const AlignedRun& run,
                                    const GroundTruthTrack& track, const std::vector<double>& p,
                                    const std::vector<effects::EffectValue>& effects,
                                    OdometrySampling sampling = OdometrySampling::kNearestTime);

// The final-pose errors (fit/final_pose_errors.h: Eq. 14 and the mean position and |heading|
// errors) of the model at p with `effects`, each run replayed by EvaluateTrajectory against its
// ground truth (tracks[i] is runs[i]'s), in parallel. Without effects it equals
// EvaluateFinalPoseErrors, which needs no track.
FinalPoseErrors EvaluateFinalPoseErrors(const RobotModelInterface& model,
                                        const std::vector<double>& p,
                                        const std::vector<effects::EffectValue>& effects,
                                        const std::vector<AlignedRun>& runs,
                                        const std::vector<const GroundTruthTrack*>& tracks,
                                        int num_threads = 0);

// Summary statistics named as the evo tool names them (evo_ape/evo_rpe "stats"): rmse, mean,
// median, std (population, ddof = 0, as numpy.std), min, max. All zero for no values.
struct SummaryStatistics {
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
  int count = 0;
};
SummaryStatistics Summarize(std::vector<double> values);

// Palacin Table 6, one row pair: averages over runs of each per-run metric (Eq. 10-14 and the
// final errors; the per-sample vectors and final poses stay empty), with the nominal ("before")
// or with the calibrated ("after") parameters.
TrajectoryErrors AverageOf(const std::vector<const TrajectoryErrors*>& runs);

// Improvement in percent as the paper's Table 6: 100 (before - after) / before (positive = better).
double ImprovementPercent(double before, double after);

}  // namespace fitcal
