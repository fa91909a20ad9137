#pragma once
// What a fitted model leaves unexplained, in a form a person can read.
//
// - Pose error (replay - ground truth) at every ground-truth sample of every run, in the world
//   frame and in the robot frame (rotated by -theta_gt).
// - The final-pose error in the run's start frame (rotated by -theta_start: repetitions of one
//   trajectory then share a frame), split into a systematic part (the mean over the repetitions
//   of a trajectory) and a non-systematic part (the scatter around it): the scatter is the noise
//   floor measured by the data itself.
// - Statistics by trajectory family (label's letters: R/G/B), heading direction alpha of the
//   motion in the robot frame (30 deg bins), rotation sign, speed; and the growth rate of the
//   robot-frame error by acceleration phase and by time within the run.
// - Repetitions: runs with the same trajectory label and the same motion (turning sign; direction
//   of travel within 30 deg, speed, yaw rate and distance within 20 %, RunFeatures::
//   repetition_group).
// - A lack-of-fit F test with the repetitions as pure error, on e, the start-frame pose errors at
//   four checkpoints (a quarter, half and three quarters through the motion, and the end): 12
//   components per run, strongly correlated, so they are whitened by their pooled pure-error
//   covariance S (rank r; trajectories with at least two repetitions):
//     S      = sum_traj sum_rep (e - mean_traj e)(...)^T / D,   D = sum_traj (n_traj - 1)
//     SS_lof = min_delta sum_traj n_traj |S^-1/2 (mean_traj e - J_traj delta)|^2
//   where J_traj is the mean derivative of e with respect to every fitted parameter (model plus
//   the effects', forward differences): what a refit on all runs could still remove is not lack
//   of fit. df_lof = r * n_traj - (identifiable parameters), df_pe = D - r + 1 (Hotelling);
//   F = SS_lof / df_lof, p = P(F(df_lof, df_pe) > F).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "diagnosis/sensor_noise_floor.h"
#include "fit/effect_fit.h"

namespace fitcal {

struct RunFeatures {
  std::string id;
  std::string trajectory;
  std::string family;  // TrajectoryFamily of the label ("R", "G", "B", ...)
  int repetition = 0;
  double alpha_rad = 0.0;       // direction of the mean robot-frame velocity while moving
  int rotation_sign = 0;        // sign of the mean yaw rate (0 when |omega| < 0.02 rad/s)
  double speed_m_s = 0.0;       // mean speed while moving
  double yaw_rate_rad_s = 0.0;  // mean yaw rate while moving
  double motion_begin_s = 0.0, motion_end_s = 0.0;  // from the window start
  // The runs this one repeats: its trajectory label, split where runs under one label differ in
  // their motion (AnalyzeResiduals; "<label> #2", ...). A session label over runs of several
  // patterns, clockwise and counter-clockwise, is no set of repetitions: their differences are
  // the model's, not noise, and read as drift with run order if taken for repetitions.
  std::string repetition_group;
  // Covariates of the run as a whole (diagnosis/covariate_structure.h).
  double distance_m = 0.0;         // path length of the replay
  double start_heading_rad = 0.0;  // world-frame heading at the window's start
  double t_start_s = 0.0;          // the window's start on the encoder clock
  double duration_s = 0.0;         // the window's length
};

struct GroupStat {
  std::string by;  // "family", "alpha_deg", ...
  std::string bin;
  int count = 0;
  // Final-pose error in the start frame (m, m, rad) for run groups; error growth rate in the
  // robot frame (m/s, m/s, rad/s) for sample groups.
  double mean[3] = {0.0, 0.0, 0.0};
  double rms[3] = {0.0, 0.0, 0.0};
};

struct LackOfFit {
  int trajectories_with_repetitions = 0;
  double df_lof = 0.0, df_pe = 0.0;
  double f = 0.0;
  double p_value = 1.0;
  bool available = false;  // needs >= 2 repetitions of some trajectory
};

struct ResidualAnalysis {
  std::vector<RunFeatures> runs;
  std::vector<TrackErrors> track;         // every ground-truth sample, world frame
  std::vector<Pose2d> final_start_frame;  // per run
  // Split of the final-pose error: RMS of the per-trajectory means (systematic) and of the
  // scatter around them (non-systematic, the noise floor), position (m) and heading (rad).
  double systematic_rms_m = 0.0, systematic_rms_rad = 0.0;
  double nonsystematic_rms_m = 0.0, nonsystematic_rms_rad = 0.0;
  LackOfFit lack_of_fit;
  // The noise floor from the sensors (sensor_noise_floor.h): estimated from every run's residual
  // track, propagated to its lack-of-fit components, and the residual of all runs tested against
  // it (no repetitions needed), with the repetitions' scatter checked against it.
  SensorNoise sensor_noise;
  SensorFloorTest sensor_floor;
  std::vector<GroupStat> groups;
  // Per run: d(final_start_frame)/d(fitted parameter), 3 x (free model parameters + effect
  // parameters), the columns the lack-of-fit test refits (forward differences).
  std::vector<Eigen::MatrixXd> final_jacobian;
  // Per run, when every run carries its wheels' absolute start angles (TrackRun::
  // start_wheel_angle_rad): d(final_start_frame)/d(a_j, b_j) at a = b = 0 for an error periodic in
  // the revolution of wheel j, w_j' = w_j (1 + a_j cos A_j + b_j sin A_j) with A_j the absolute
  // wheel angle (an eccentric wheel, r(A) = r0 (1 + e cos(A - A0))), 3 x (2 wheels); forward
  // differences. Empty otherwise.
  std::vector<Eigen::MatrixXd> wheel_angle_jacobian;
};

// The lack-of-fit test counts as fitted every parameter of p and of the model's effects (it
// subtracts their linearised refit on all runs). `runs` by address: Diagnose's training and
// validation runs in one list without copying them.
ResidualAnalysis AnalyzeResiduals(const RobotModelInterface& robot_model,
                                  const std::vector<double>& p, const EffectModel& model,
                                  const std::vector<const TrackRun*>& runs, int num_threads = 0);

// Human-readable tables (Markdown).
std::string FormatResidualAnalysis(const ResidualAnalysis& analysis);
// Every ground-truth sample's error:
// run,t,err_x_world,err_y_world,err_theta,err_x_robot,err_y_robot
std::string ResidualSamplesCsv(const ResidualAnalysis& analysis);

}  // namespace fitcal
