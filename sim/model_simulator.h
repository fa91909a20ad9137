#pragma once
// Simulated calibration runs of any robot model (models/model_interface.h): a trajectory is a
// list of body twists held for given durations; the simulator turns it into what a recorder
// would log (encoder channels, ground truth) for a robot whose true parameters are known.
//
// Two motion and noise models. With SimulationOptions::stepped, the flower's time-stepped physics
// (SteppedOptions below: controller lag, slip, jittered encoders, irregular ground truth; the
// shipped data/flower is made so: omni3's scenario, sim/model_scenarios.h). Without it, perfect
// tracking:
//
// - Commanded twist. Segments follow each other with raised-cosine ramps of ramp_time_s centred
//   on every segment boundary (also from rest into the first segment and back to rest after the
//   last): v(t) = v_prev + (v_next - v_prev) (1 - cos(pi u)) / 2, u = (t - t_b + ramp/2) / ramp.
//   Velocity and acceleration are continuous, and because the ramp is antisymmetric about the
//   boundary every segment keeps the integral it was given: a segment of (v, omega) for T seconds
//   still covers v T metres and omega T radians. Segments must last at least ramp_time_s. The
//   run starts with rest_before_s and ends with rest_after_s at rest.
// - The true robot follows the commanded twist exactly (as under a perfect tracking controller):
//   its channel values are the model's inverse kinematics with the TRUE parameters,
//   ChannelsForTwist(p_true, v(t)), evaluated on a fine time grid (steps of at most substep_s,
//   refined so that every encoder and ground-truth time is a grid point) at each step's middle.
//   A twist the model cannot drive (ChannelsForTwist false) is an error.
// - Ground truth: the true model replayed on that fine grid (RobotModelInterface::Replay with
//   p_true, piecewise-constant channel values), sampled every ground_truth_period_s, plus white
//   Gaussian noise: gt_position_sigma_m per axis and gt_heading_sigma_rad.
// - Encoders, every encoder_period_s (row 0 only sets the start time):
//     wheel-rate channels: the true wheel angle advance over the interval (exact integral of the
//       fine rates) plus white Gaussian noise of wheel_rate_sigma_rad_s * dt per interval (an
//       encoder rate noise, independent per interval: the odometry's random walk); with
//       ticks_per_rev[i] > 0 the accumulated measured angle is then counted in whole ticks
//       (floor), so the quantisation error stays below one tick and does not accumulate; the log
//       holds the mean rate over the interval (counted angle advance / dt).
//     angle channels: the reading at each row time plus white Gaussian noise angle_sigma_rad; the
//       interval value is the mean of the two readings (as the loader makes it, robot.h). With
//       `dynamics` the model's own state gives the channels step by step and its encoders' readings.
// - Start pose: start_pose, moved by a uniform offset in +-start_position_range_m per axis and a
//   uniform heading in [-pi, pi) when random_start_heading; recorded in RunLog::start_pose only
//   when record_start_pose (otherwise the fit takes it from the noisy ground truth).
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

// The flower simulator's physics (Palacin's APR-02 as data/flower was made; stepped_run.h): a
// time-stepped run in which a wheel controller follows the NOMINAL robot's inverse kinematics
// with a first-order lag, the wheels slip, the encoders latch with jitter and the ground truth
// comes at irregular times. Selected by SimulationOptions::stepped; the defaults are the
// flower's (docs/simulate.md).
struct ControllerLagOptions {
  // Each channel follows its target through a first-order lag, rest to rest (start/stop
  // transients): x += (1 - exp(-h / tau)) (target - x) per substep h.
  double time_constant_s = 0.12;
};
struct SlipOptions {
  // Contact rate = wheel rate (1 + s), s a per-wheel Ornstein-Uhlenbeck process of stationary
  // sigma `sigma` and correlation time `correlation_time_s`: the non-systematic error that makes
  // repetitions scatter. Wheel-rate channels only.
  double sigma = 0.003;
  double correlation_time_s = 0.5;
};
struct EncoderLatchOptions {
  // Counts latched every encoder period (SimulationOptions::encoder_period_s) plus a uniform
  // jitter in [-jitter_s, jitter_s] (APR-02's 10 ms PID period), at the first substep end at or
  // after the scheduled time; quantised by SimulationOptions::ticks_per_rev.
  double jitter_s = 0.0005;
};
struct IrregularGroundTruthOptions {
  // Samples at intervals uniform in [period_min_s, period_max_s] (Palacin Sec. 2.5: SLAM every
  // 200-300 ms), the first within period_max_s of the start.
  double period_min_s = 0.2;
  double period_max_s = 0.3;
};

// What a test may change at every substep of a stepped run, after the library effects: the
// channels' contact rates (rad/s, robot order; angle channels as they are), the body twist and
// an additive world velocity (m/s).
struct SteppedState {
  double t_s = 0.0;                         // since the run's start
  double time_since_motion_s = -1.0;        // < 0 before the first segment starts
  const double* channel_value = nullptr;    // the controller's state, robot order
  const double* wheel_angle_rad = nullptr;  // integrated channel values since the start
  Pose2d pose;
};
using SteppedHook = std::function<void(const SteppedState&, double* contact_rate, Twist* v_body,
                                       double* v_world_xy)>;

struct SteppedOptions {
  // The robot the controller commands with (ChannelsForTwist); empty = the true robot.
  std::vector<double> commanded_parameters;
  ControllerLagOptions controller;
  SlipOptions slip;
  EncoderLatchOptions encoder;
  IrregularGroundTruthOptions ground_truth;
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

struct SimulationOptions {
  double encoder_period_s = 0.05;
  double ground_truth_period_s = 0.1;
  double substep_s = 0.002;  // longest step of the fine truth grid
  double ramp_time_s = 0.4;
  double rest_before_s = 0.5;
  double rest_after_s = 0.5;

  // Per channel (robot order): ticks per wheel revolution, 0 = no quantisation. Empty = none.
  std::vector<double> ticks_per_rev;
  double wheel_rate_sigma_rad_s = 0.0;
  // Each wheel channel's counted advance over an encoder interval scaled by (1 + N(0, sigma)):
  // floor roughness, small slips (Doebbler's non-systematic error, asoc-tables).
  double wheel_relative_sigma = 0.0;
  double angle_sigma_rad = 0.0;
  double gt_position_sigma_m = 0.0;
  double gt_heading_sigma_rad = 0.0;

  Pose2d start_pose;
  double start_position_range_m = 0.0;
  bool random_start_heading = false;
  bool record_start_pose = false;

  std::uint64_t seed = 1;

  // Set: the flower's time-stepped physics (above) in place of perfect tracking; ramp_time_s,
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
