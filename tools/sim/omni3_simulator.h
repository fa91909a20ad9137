#pragma once
// Simulated calibration runs of a three-wheeled omni robot. The noise model (also in README.md,
// "Simulator"):
//
// - The wheel controller turns a motion command into target wheel rates with the *commanded*
//   (nominal) parameters, Eq. 1; each wheel follows its target through a first-order lag with
//   time constant controller_time_constant_s (start/stop transients), from rest to rest.
// - The robot moves with the *true* parameters: body velocity = M_true^-1 * (contact rate), where
//   the contact rate is the wheel rate times (1 + slip), slip a per-wheel Ornstein-Uhlenbeck
//   process (sigma slip_sigma, correlation time slip_correlation_time_s): the non-systematic error
//   that makes repetitions scatter. Integrated at substep_s with the midpoint heading.
// - Encoders count wheel angle in encoder_counts_per_rev steps, latched every encoder_period_s with
//   a jitter of up to encoder_jitter_s; the log holds the mean rate over each interval.
// - Ground truth samples the true pose at irregular intervals, uniform in
//   [gt_period_min_s, gt_period_max_s], with white Gaussian noise (gt_position_sigma_m per axis,
//   gt_heading_sigma_rad); it starts up to one period after the encoders.
// - Every run starts at a random world pose (uniform in +-start_position_range_m, any heading).
// Reproducible: run i of a simulation draws from its own generator seeded by (seed, i), so the
// output does not depend on thread count or platform.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "odometry/effects.h"
#include "odometry/omni3_model.h"
#include "odometry/robot_description.h"
#include "odometry/run_log.h"
#include "tools/sim/flower_scenario.h"

namespace fitcal::sim {


struct Omni3SimulationOptions {
  omni3::Parameters true_robot = PalacinTable5Parameters();
  omni3::Parameters commanded_robot = PalacinNominalParameters();
  std::vector<MotionCommand> trajectories = FlowerTrajectories();
  int repetitions = 10;
  std::uint64_t seed = 1;

  double encoder_period_s = 0.010;  // APR-02: 10 ms PID period
  double encoder_jitter_s = 0.0005;
  int encoder_counts_per_rev = 4096;
  double controller_time_constant_s = 0.12;
  double rest_before_s = 0.5;
  double rest_after_s = 1.5;
  double substep_s = 0.0005;

  double slip_sigma = 0.003;
  double slip_correlation_time_s = 0.5;

  double gt_period_min_s = 0.2;  // Palacin Sec. 2.5: SLAM every 200-300 ms
  double gt_period_max_s = 0.3;
  double gt_position_sigma_m = 0.002;
  double gt_heading_sigma_rad = 0.2 * M_PI / 180.0;

  double start_position_range_m = 2.0;

  // Wheels' absolute angles: with random_wheel_start_angle each run starts at uniformly random
  // absolute wheel angles A_i(0) (a robot whose encoder counts run on between runs), drawn from
  // a generator of their own (the other draws stay as without it), and the log carries them
  // (EncoderLog::start_angle_rad, as a recorder of cumulative counts would). wheel_eccentricity
  // e_i makes wheel i's rolling radius r_i (1 + e_i cos A_i) (an eccentric hub or tyre): an
  // error periodic in the wheel's revolution.
  bool random_wheel_start_angle = false;
  std::array<double, 3> wheel_eccentricity{};

  // Effects the nine parameters lack (odometry/effects.h); the written data set names none of them.
  // Library effects (odometry/effects.h) act at every substep with the true wheel state: rate
  // effects on the contact rates, body effects on M_true^-1 * contact, world effects added to
  // the world velocity, and the time offset shifts every ground-truth stamp by +latency.
  std::vector<effects::EffectValue> injected_effects;
  // Anything else: called at every substep after the library effects; may change the contact
  // rates (rad/s), the robot-frame velocity (vx, vy, omega) and the additive world velocity.
  struct InjectionState {
    double t_s = 0.0;                   // since the run's start
    double time_since_motion_s = -1.0;  // < 0 before the motion command starts
    Eigen::Vector3d wheel_rate = Eigen::Vector3d::Zero();
    Eigen::Vector3d wheel_angle_rad = Eigen::Vector3d::Zero();
    Pose2d pose;
  };
  std::function<void(const InjectionState&, Eigen::Vector3d* contact_rate, Eigen::Vector3d* v_body,
                     Eigen::Vector2d* v_world)>
      injection_hook;
};

// The default options without noise: no slip, no ground-truth noise, no encoder jitter and
// near-ideal encoders (2^22 counts/rev), one repetition. What then remains between the
// simulator and Eq. 4 is the replay's discretisation.
Omni3SimulationOptions NoiseFreeSimulationOptions();

struct SimulatedRun {
  RunLog log;              // what a recorder would have written
  Pose2d true_final_pose;  // noise-free truth at the last encoder time
};

// All trajectories x repetitions, ordered by repetition then trajectory. Ids are
// "<label>-rep<NN>". Throws std::invalid_argument on inconsistent options.
std::vector<SimulatedRun> SimulateOmni3(const Omni3SimulationOptions& options);

}  // namespace fitcal::sim
