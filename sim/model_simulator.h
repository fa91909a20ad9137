#pragma once
// Simulated calibration runs of any robot model (models/model_interface.h): a trajectory is a
// list of body twists held for given durations; the simulator turns it into what a recorder
// would log (encoder channels, ground truth) for a robot whose true parameters are known. Two
// motion and noise models (docs/simulate.md: their tables of effects and defaults): with
// SimulationOptions::stepped the flower's time-stepped physics (SteppedOptions below), without it
// perfect tracking:
// - Commanded twist: raised-cosine ramps of kRampTimeS centred on every segment boundary (from
//   and back to rest too), v(t) = v_prev + (v_next - v_prev) (1 - cos(pi u)) / 2,
//   u = (t - t_b + ramp/2) / ramp. The ramp is antisymmetric about the boundary, so every segment
//   keeps its integral (v T metres, omega T radians); segments must last at least kRampTimeS.
// - The true robot follows it exactly: ChannelsForTwist(p_true, v(t)) at the middle of each step
//   of a fine grid (steps <= substep_s, every encoder and ground-truth time a grid point; a twist
//   the model cannot drive is an error), replayed with p_true for the ground truth, sampled every
//   ground_truth_period_s with white noise gt_position_sigma_m per axis, gt_heading_sigma_rad.
// - Encoders every encoder_period_s: a wheel channel's exact angle advance plus white noise of
//   wheel_rate_sigma_rad_s * dt per interval (a random walk), counted in whole ticks of the
//   accumulated angle (floor: the quantisation error stays below one tick), logged as the mean
//   rate; an angle channel read at each row with white noise angle_sigma_rad, the interval's value
//   the mean of its two readings (robot.h). With `dynamics` the model's own state gives both.
// - Start pose: start_pose, moved uniformly by +-start_position_range_m per axis and to a uniform
//   heading when random_start_heading; recorded only when record_start_pose.
// Reproducible: run i draws from its own generator seeded by (seed, i) with a hand-written
// Box-Muller normal, so the output does not depend on the standard library or thread count.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "models/model_extras.h"
#include "models/model_interface.h"
#include "models/trajectory_spec.h"
#include "odometry/effects.h"
#include "odometry/run_log.h"

namespace fitcal::sim {

// What a test may change at every substep of a stepped run, after the library effects: the
// channels' contact rates (rad/s, robot order; angle channels as they are), the body twist and
// an additive world velocity (m/s).
struct SteppedState {
  double t_s = 0.0;                       // since the run's start
  double time_since_motion_s = -1.0;      // < 0 before the first segment starts
  const double* channel_value = nullptr;  // the controller's state, robot order
  Pose2d pose;
};
using SteppedHook = std::function<void(const SteppedState&, double* contact_rate, Twist* v_body,
                                       double* v_world_xy)>;

// The flower simulator's physics, selected by SimulationOptions::stepped: the per-substep
// equations and the order of the draws in stepped_run.h, the defaults (the flower's) in
// docs/simulate.md. The controller follows the NOMINAL robot's inverse kinematics.
struct SteppedOptions {
  // The robot the controller commands with (ChannelsForTwist); empty = the true robot.
  std::vector<double> commanded_parameters;
  double controller_time_constant_s = 0.12;  // tau of each channel's first-order lag
  // Contact rate = wheel rate (1 + s), s a per-wheel Ornstein-Uhlenbeck process: the
  // non-systematic error that makes repetitions scatter. Wheel-rate channels only.
  double slip_sigma = 0.003;
  double slip_correlation_time_s = 0.5;
  // Counts latched every encoder period plus a uniform jitter in [-jitter_s, jitter_s] (APR-02's
  // 10 ms PID period), at the first substep end at or after the scheduled time.
  double encoder_jitter_s = 0.0005;
  // Ground truth sampled at intervals uniform in [min, max] (Palacin Sec. 2.5: SLAM every
  // 200-300 ms), the first within the max of the start.
  double gt_period_min_s = 0.2;
  double gt_period_max_s = 0.3;
  double substep_s = 0.0005;  // integration step of the true motion (midpoint heading)

  // Wheels' absolute angles: with random_wheel_start_angle each run starts at uniformly random
  // absolute wheel angles (a robot whose counts run on between runs), drawn from a generator of
  // their own (the other draws stay as without it), carried in EncoderLog::start_angle_rad.
  // wheel_eccentricity[i] e makes wheel i roll on r (1 + e cos A): an error periodic in the
  // wheel's revolution. Empty = none.
  bool random_wheel_start_angle = false;
  std::vector<double> wheel_eccentricity;

  // Library effects (odometry/effects.h) at every substep with the true channel state: rate
  // effects on the contact rates, body effects on the twist, world effects on the world
  // velocity; a time offset shifts every ground-truth stamp by +latency. The data set names none.
  std::vector<effects::EffectValue> injected_effects;
  SteppedHook hook;  // anything else, after the library effects
};

inline constexpr double kRampTimeS = 0.4;  // the commanded twist's ramps (above)

struct SimulationOptions {
  double encoder_period_s = 0.05;
  double ground_truth_period_s = 0.1;
  double substep_s = 0.002;  // longest step of the fine truth grid
  double rest_before_s = 0.5;
  double rest_after_s = 0.5;

  // Per channel (robot order): ticks per wheel revolution, 0 = no quantisation. Empty = none.
  std::vector<double> ticks_per_rev;
  double wheel_rate_sigma_rad_s = 0.0;
  // Each wheel channel's counted advance over an encoder interval scaled by (1 + N(0, sigma)):
  // floor roughness, small slips (Doebbler's non-systematic error, paper-tables --model asoc).
  double wheel_relative_sigma = 0.0;
  double angle_sigma_rad = 0.0;
  double gt_position_sigma_m = 0.0;
  double gt_heading_sigma_rad = 0.0;

  Pose2d start_pose;
  double start_position_range_m = 0.0;
  bool random_start_heading = false;
  bool record_start_pose = false;

  std::uint64_t seed = 1;

  // Set: the flower's time-stepped physics (above) in place of perfect tracking; the ramps,
  // ground_truth_period_s and wheel_rate_sigma_rad_s are then unused.
  std::optional<SteppedOptions> stepped;
  // Set: the model integrates channels of its own state (ModelExtras::scenario.dynamics: an
  // ASOC castor's angle) in place of ChannelsForTwist; perfect tracking only.
  ChannelDynamicsFactory dynamics;

  // Empty when valid, else what is wrong.
  std::string Check(int num_channels) const;
};

struct ModelSimulatedRun {
  RunLog log;  // what the loader hands over (interval values, robot channel order)
  // What the recorder writes: the encoder CSV's channel columns (the robot's rate_column names,
  // robot order) and one row per encoder time (wheel rates in rad/s over the interval ending at
  // the row, 0 in row 0; angles as read at the row).
  std::vector<std::string> encoder_columns;
  std::vector<std::vector<double>> recorded;
  Pose2d true_final_pose;  // noise-free truth at the last encoder time
  Pose2d true_start_pose;
};

// One run per trajectory spec, in order. Ids are "<label>-rep<NN>". Throws std::invalid_argument
// for invalid options, a segment shorter than the ramp, or a twist the model cannot drive.
std::vector<ModelSimulatedRun> SimulateRuns(const RobotModelInterface& model,
                                            const std::vector<double>& true_parameters,
                                            const std::vector<TrajectorySpec>& trajectories,
                                            const SimulationOptions& options);

// How the encoder CSV writes its numbers: kRoundTrip at full precision (%.17g: the loader reads
// back the same doubles); kRecorder as a recorder would and as data/flower holds them (times
// %.6f, values %.9g: io::EncoderCsv).
enum class EncoderCsvDigits { kRoundTrip, kRecorder };

// The encoder CSV of a run: header `t,<encoder_columns>`, then the recorded rows.
std::string SimulatedEncoderCsv(const ModelSimulatedRun& run,
                                EncoderCsvDigits digits = EncoderCsvDigits::kRoundTrip);

// Writes a data set: <dir>/dataset.yaml, <dir>/robot.yaml (robot_yaml_text as given) and
// runs/<id>_encoders.csv, runs/<id>_ground_truth.csv per run, each file atomically. Creates the
// directories; throws std::runtime_error when a file cannot be written.
void WriteSimulatedDataset(const std::string& dir, const std::string& robot_yaml_text,
                           const std::vector<ModelSimulatedRun>& runs,
                           EncoderCsvDigits digits = EncoderCsvDigits::kRoundTrip);

}  // namespace fitcal::sim
