#pragma once
// An independent simulator of a differential drive for the tests: it shares no code with
// fitcal's replay, models or simulator (it includes only the standard library), so a test that
// fits its data checks fitcal against physics fitcal was not written with.
//
// Physics, integrated in continuous time (1 kHz steps, each step an exact arc):
// - Motors follow the commanded wheel speeds with a first-order lag (tau_s): accelerations are
//   finite, so traction is too.
// - Gear train: the encoder sits on the motor shaft; the wheel follows the motor through a dead
//   band of backlash_rad (the wheel angle moves only when the motor pushes it at either edge), so
//   the play is crossed at the start and again on every reversal of the motor.
// - Wheel-ground contact: the contact point moves at u = r phi_dot (1 - s), the longitudinal
//   slip s = k_a (r phi_ddot) + s_walk: proportional to the traction (the wheel's tangential
//   acceleration, positive when driving, negative when braking) plus a slowly wandering slip
//   (an Ornstein-Uhlenbeck random walk of stationary sigma walk_sigma and correlation time
//   walk_tau_s). Both are zero-mean, so the geometric radii stay the effective ones.
// - Body: v = (u_right + u_left) / 2, omega = (u_right - u_left) / b (rigid body, no lateral slip).
// Mechanisms (Mechanisms below, every one off by default; each is a physical cause, written
// without fitcal's effect equations, for `fitcal diagnose` to trace): tread asymmetry, an
// eccentric wheel hub, slip growing with speed, turn scrub, a traction limit, contact patches
// that move inward as a turn tightens, a slope with creeping tyres, a late and offset motion
// capture marker; and two that fitcal's effect library does not hold: a carpet's grain (slip that
// depends on the world heading) and centripetal side slip.
// Sensors:
// - Encoders: cumulative ticks floor(encoder_scale phi_motor / 2 pi * ticks_per_rev), every
//   encoder_period_s.
// - Motion capture: the true pose every mocap_period_s plus white noise (xy_sigma_m per axis,
//   theta_sigma_rad).
// Trajectories ("everyday driving"): random straights, arcs of either sense and turns in place,
// with short stops between them, until the path reaches length_m.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace independent_sim {

constexpr double kTwoPi = 6.283185307179586;

struct DiffDriveGeometry {
  double r_right_m = 0.0418;
  double r_left_m = 0.0421;
  double separation_m = 0.2035;
};

struct ContactPhysics {
  double traction_slip_per_m_s2 = 0.005; // k_a: slip per m/s^2 of the wheel's acceleration
  double walk_sigma = 0.0005;            // stationary sigma of the wandering slip
  double walk_tau_s = 3.0;
  double backlash_rad = 0.0;  // dead band of the gear train (wheel angle)
  double motor_tau_s = 0.08;
};

// Physical causes of odometry error beyond the geometry, each 0 (absent) by default. They act in
// the continuous-time integration, not on the recorded data.
struct Mechanisms {
  // Directional tread: the rim rolls on radius r (1 + tread_asymmetry) forward and
  // r (1 - tread_asymmetry) backward.
  double tread_asymmetry = 0.0;
  // Eccentric hub: the rolling radius is r (1 + e cos(wheel angle + phase)), the wheel angle
  // counted from the run's start (both wheels mounted alike).
  double hub_eccentricity = 0.0;
  double hub_phase_rad = 0.0;
  // Tyre hysteresis: rolling resistance, and the creep it needs, grow with speed; slip ratio
  // speed_slip_s_per_m * |rim speed|.
  double speed_slip_s_per_m = 0.0;
  // Turn scrub: the tyres twist on the floor as the body turns, loading both wheels; slip ratio
  // scrub_slip_s_per_rad * |body yaw rate|.
  double scrub_slip_s_per_rad = 0.0;
  // Traction creep (brush tyre, small slip): the slip ratio is proportional to the traction
  // force, i.e. to the wheel's acceleration along its motion: traction_creep_s2_per_m * a * sign of
  // the rate (speeding up loses ground, braking overruns; ContactPhysics' traction_slip_per_m_s2
  // keeps the other tests' data and ignores the sign of the rate).
  double traction_creep_s2_per_m = 0.0;
  // Traction limit (friction mu g): the contact point's speed changes by at most this much per
  // second; faster spin-up slides (the body lags the wheel), faster braking skids (it overruns).
  double traction_limit_m_s2 = 0.0;
  // Contact patches that move inward as the turn tightens: each wheel's effective contact sits
  // contact_shift_m * s nearer the centre, s = |u_R - u_L| / (|u_R| + |u_L|) (0 straight, 1 in a
  // pivot, where the patches twist about their inner edges).
  double contact_shift_m = 0.0;
  // A floor sloping down along slope_direction_rad (world frame): while the wheels roll (static
  // friction holds at rest) the compliant tyres creep downhill at slope_creep_m_s, whatever the
  // heading (isotropic creep).
  double slope_creep_m_s = 0.0;
  double slope_direction_rad = 0.0;
  // Motion capture: the marker sits at (marker_x_m, marker_y_m) in the body frame, and a sample
  // taken at t is stamped t + mocap_latency_s.
  double marker_x_m = 0.0, marker_y_m = 0.0;
  double mocap_latency_s = 0.0;
  // Outside fitcal's effect library:
  // Carpet grain: the pile lies along grain_direction_rad; rolling with it slips less than
  // against it: slip ratio carpet_grain * cos(heading - grain_direction_rad).
  double carpet_grain = 0.0;
  double grain_direction_rad = 0.0;
  // Centripetal side slip: the body skids outward in a turn, lateral velocity
  // -side_slip_s * v * omega (the lateral tyre force is m v omega).
  double side_slip_s = 0.0;
};

struct Sensors {
  int ticks_per_rev = 4096;
  double encoder_period_s = 0.02;
  double mocap_period_s = 0.01;
  double mocap_xy_sigma_m = 0.001;
  double mocap_theta_sigma_rad = 0.0017;  // 0.1 deg
  // Counts per motor radian relative to ticks_per_rev / 2 pi (a gear ratio or disc off spec).
  double encoder_scale = 1.0;
};

struct Drive {
  double length_m = 40.0;
  double speed_m_s = 0.3;
  double spin_rate_rad_s = 1.0;
};

struct Pose {
  double x = 0.0, y = 0.0, theta = 0.0;
};

struct SimulatedRun {
  // Encoder samples: time and cumulative ticks (right, left).
  std::vector<double> encoder_t_s;
  std::vector<std::int64_t> ticks_right, ticks_left;
  // The true pose at every encoder time (the TRUE motion, for checks).
  std::vector<Pose> true_pose_at_encoder;
  // Motion capture: time and the noisy pose.
  std::vector<double> mocap_t_s;
  std::vector<Pose> mocap;
  double path_m = 0.0;
};

// A commanded body twist held for a duration.
struct Command {
  double v_m_s = 0.0, omega_rad_s = 0.0, duration_s = 0.0;
};

inline std::vector<Command> EverydayCommands(const Drive& drive, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Command> out;
  double path = 0.0;
  while (path < drive.length_m) {
    const double pick = u(rng);
    const double sense = u(rng) < 0.5 ? -1.0 : 1.0;
    if (pick < 0.35) {  // straight, 1-3 m
      const double length = 1.0 + 2.0 * u(rng);
      out.push_back({drive.speed_m_s, 0.0, length / drive.speed_m_s});
      path += length;
    } else if (pick < 0.8) {  // arc, radius 0.4-2 m, 45-180 deg
      const double radius = 0.4 + 1.6 * u(rng);
      const double angle = (0.25 + 0.75 * u(rng)) * kTwoPi / 2.0;
      out.push_back({drive.speed_m_s, sense * drive.speed_m_s / radius,
                     angle * radius / drive.speed_m_s});
      path += angle * radius;
    } else {  // turn in place, 90-180 deg
      const double angle = (0.5 + 0.5 * u(rng)) * kTwoPi / 2.0;
      out.push_back({0.0, sense * drive.spin_rate_rad_s, angle / drive.spin_rate_rad_s});
    }
    if (u(rng) < 0.4) out.push_back({0.0, 0.0, 0.6});  // a stop
  }
  out.push_back({0.0, 0.0, 1.0});  // come to rest
  return out;
}

// Runs for closing the loop (`fitcal diagnose`): manoeuvres that expose what a calibration's
// constant parameters cannot absorb - straights and arcs forward and in reverse at two speeds,
// turns in place both ways, a stop after every manoeuvre (starts, stops and reversals of each
// wheel) - in random order and sizes, `manoeuvres` of them.
struct Manoeuvres {
  double slow_m_s = 0.15, fast_m_s = 0.35;
  double spin_rate_rad_s = 1.2;
  int manoeuvres = 10;
  double stop_s = 0.5;
};

inline std::vector<Command> ManoeuvreCommands(const Manoeuvres& plan, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Command> out;
  for (int k = 0; k < plan.manoeuvres; ++k) {
    const double pick = u(rng);
    const double sense = u(rng) < 0.5 ? -1.0 : 1.0;
    const double direction = u(rng) < 0.35 ? -1.0 : 1.0;  // reverse a third of the time
    const double speed = direction * (u(rng) < 0.5 ? plan.slow_m_s : plan.fast_m_s);
    if (pick < 0.3) {  // straight, 0.5-1.5 m
      const double length = 0.5 + u(rng);
      out.push_back({speed, 0.0, length / std::abs(speed)});
    } else if (pick < 0.7) {  // arc, radius 0.3-1.2 m, 60-180 deg
      const double radius = 0.3 + 0.9 * u(rng);
      const double angle = (1.0 + 2.0 * u(rng)) * kTwoPi / 6.0;
      out.push_back({speed, sense * std::abs(speed) / radius, angle * radius / std::abs(speed)});
    } else {  // turn in place, 90-270 deg
      const double angle = (0.5 + u(rng)) * kTwoPi / 4.0 * 1.5;
      out.push_back({0.0, sense * plan.spin_rate_rad_s, angle / plan.spin_rate_rad_s});
    }
    out.push_back({0.0, 0.0, plan.stop_s});
  }
  out.push_back({0.0, 0.0, 0.5});  // come to rest
  return out;
}

// A repetition of `commands` as a robot drives it again: every command's speeds and duration
// scaled by independent factors 1 +- fraction (uniform), so repetitions differ in their encoder
// logs as real ones do while staying repetitions of one motion.
inline std::vector<Command> RepeatCommands(std::vector<Command> commands, double fraction,
                                           std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-fraction, fraction);
  for (Command& c : commands) {
    const double speed = 1.0 + u(rng);
    c.v_m_s *= speed;
    c.omega_rad_s *= speed;
    c.duration_s *= 1.0 + u(rng);
  }
  return commands;
}

namespace detail {

inline double Sign(double x) { return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); }

// The state of one wheel between integration steps.
struct WheelState {
  double motor_rate = 0.0, motor_angle = 0.0;
  double wheel_angle = 0.0, wheel_rate = 0.0;
  double walk = 0.0;
  double ground_speed = 0.0;  // of the contact point, m/s (the traction limit's memory)
};

// The wheel follows the motor through the gear play: it moves only when the motor pushes it at
// an edge of the dead band. Returns the wheel's new rate.
inline double ThroughGearPlay(double backlash_rad, double step_s, WheelState* w) {
  const double half = backlash_rad / 2.0;
  double next = w->wheel_angle;
  if (w->motor_angle - next > half) next = w->motor_angle - half;
  if (w->motor_angle - next < -half) next = w->motor_angle + half;
  const double rate = (next - w->wheel_angle) / step_s;
  w->wheel_angle = next;
  return rate;
}

}  // namespace detail

// One run from the origin (pose 0, 0, 0) driving `commands`; rng draws the noise (wandering slip,
// motion capture).
inline SimulatedRun SimulateCommands(const DiffDriveGeometry& g, const ContactPhysics& physics,
                                     const Mechanisms& m, const Sensors& sensors,
                                     const std::vector<Command>& commands, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  constexpr double kStepS = 0.001;
  const double r[2] = {g.r_right_m, g.r_left_m};
  detail::WheelState wheel[2];
  const double walk_decay = std::exp(-kStepS / physics.walk_tau_s);
  const double walk_kick = physics.walk_sigma * std::sqrt(1.0 - walk_decay * walk_decay);
  Pose pose;
  SimulatedRun run;
  double t = 0.0, next_encoder = 0.0, next_mocap = 0.0, omega = 0.0;
  const auto ticks = [&](int w) {
    return static_cast<std::int64_t>(std::floor(sensors.encoder_scale * wheel[w].motor_angle /
                                                kTwoPi * sensors.ticks_per_rev));
  };
  const auto record = [&]() {
    while (t >= next_encoder - 1e-12) {
      run.encoder_t_s.push_back(next_encoder);
      run.ticks_right.push_back(ticks(0));
      run.ticks_left.push_back(ticks(1));
      run.true_pose_at_encoder.push_back(pose);
      next_encoder += sensors.encoder_period_s;
    }
    while (t >= next_mocap - 1e-12) {
      // The marker's pose, sampled now and stamped late by the capture pipeline.
      const double c = std::cos(pose.theta), s = std::sin(pose.theta);
      const double x = pose.x + c * m.marker_x_m - s * m.marker_y_m;
      const double y = pose.y + s * m.marker_x_m + c * m.marker_y_m;
      run.mocap_t_s.push_back(next_mocap + m.mocap_latency_s);
      run.mocap.push_back({x + sensors.mocap_xy_sigma_m * normal(rng),
                           y + sensors.mocap_xy_sigma_m * normal(rng),
                           pose.theta + sensors.mocap_theta_sigma_rad * normal(rng)});
      next_mocap += sensors.mocap_period_s;
    }
  };
  record();
  for (const Command& c : commands) {
    const double target[2] = {(c.v_m_s + c.omega_rad_s * g.separation_m / 2.0) / r[0],
                              (c.v_m_s - c.omega_rad_s * g.separation_m / 2.0) / r[1]};
    const int steps = static_cast<int>(std::round(c.duration_s / kStepS));
    for (int i = 0; i < steps; ++i) {
      double ground_speed[2], rim_speed[2];
      bool rolling = false;
      for (int w = 0; w < 2; ++w) {
        detail::WheelState& s = wheel[w];
        s.motor_rate += (target[w] - s.motor_rate) * kStepS / physics.motor_tau_s;
        s.motor_angle += s.motor_rate * kStepS;
        const double rate = detail::ThroughGearPlay(physics.backlash_rad, kStepS, &s);
        const double acceleration_m_s2 = r[w] * (rate - s.wheel_rate) / kStepS;
        s.wheel_rate = rate;
        s.walk = walk_decay * s.walk + walk_kick * normal(rng);
        const double radius = r[w] * (1.0 + m.tread_asymmetry * detail::Sign(rate)) *
                              (1.0 + m.hub_eccentricity * std::cos(s.wheel_angle + m.hub_phase_rad));
        rim_speed[w] = radius * rate;
        const double slip = physics.traction_slip_per_m_s2 * acceleration_m_s2 + s.walk +
                            m.traction_creep_s2_per_m * acceleration_m_s2 * detail::Sign(rate) +
                            m.speed_slip_s_per_m * std::abs(rim_speed[w]) +
                            m.scrub_slip_s_per_rad * std::abs(omega) +
                            m.carpet_grain * std::cos(pose.theta - m.grain_direction_rad);
        double ground = rim_speed[w] * (1.0 - slip);
        if (m.traction_limit_m_s2 > 0.0) {
          const double most = m.traction_limit_m_s2 * kStepS;
          ground = s.ground_speed + std::clamp(ground - s.ground_speed, -most, most);
        }
        s.ground_speed = ground;
        ground_speed[w] = ground;
        rolling = rolling || std::abs(rate) > 0.05;
      }
      const double v = 0.5 * (ground_speed[0] + ground_speed[1]);
      const double rim_sum = std::abs(rim_speed[0]) + std::abs(rim_speed[1]);
      const double turn = rim_sum > 0.0 ? std::abs(rim_speed[0] - rim_speed[1]) / rim_sum : 0.0;
      const double separation = g.separation_m - 2.0 * m.contact_shift_m * turn;
      omega = (ground_speed[0] - ground_speed[1]) / separation;
      // Exact arc over the step.
      const double heading_mid = pose.theta + 0.5 * omega * kStepS;
      const double chord = std::abs(omega) > 1e-12
                               ? 2.0 * v / omega * std::sin(0.5 * omega * kStepS)
                               : v * kStepS;
      pose.x += chord * std::cos(heading_mid);
      pose.y += chord * std::sin(heading_mid);
      if (m.side_slip_s != 0.0) {
        const double lateral = -m.side_slip_s * v * omega * kStepS;
        pose.x -= lateral * std::sin(heading_mid);
        pose.y += lateral * std::cos(heading_mid);
      }
      if (m.slope_creep_m_s != 0.0 && rolling) {
        pose.x += m.slope_creep_m_s * std::cos(m.slope_direction_rad) * kStepS;
        pose.y += m.slope_creep_m_s * std::sin(m.slope_direction_rad) * kStepS;
      }
      pose.theta += omega * kStepS;
      run.path_m += std::abs(v) * kStepS;
      t += kStepS;
      record();
    }
  }
  return run;
}

// One everyday run from the origin (pose 0, 0, 0); the seed draws the commands, then the noise.
inline SimulatedRun SimulateDiffDrive(const DiffDriveGeometry& g, const ContactPhysics& physics,
                                      const Sensors& sensors, const Drive& drive,
                                      std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::vector<Command> commands = EverydayCommands(drive, rng);
  return SimulateCommands(g, physics, Mechanisms{}, sensors, commands, rng);
}

// A run of a data set: its trajectory label and repetition number.
struct LabelledRun {
  std::string trajectory;
  int repetition = 1;
  SimulatedRun run;
};

// Writes `runs` as a fitcal data set (docs/dataset-format.md) under `dir`: dataset.yaml, a
// diff_drive robot.yaml with `nominal` geometry and ticks encoders, one encoder CSV (cumulative
// ticks, right then left) and one ground-truth CSV per run, named <trajectory>_<repetition>.
inline void WriteLabelledDataSet(const std::filesystem::path& dir,
                                 const std::vector<LabelledRun>& runs,
                                 const DiffDriveGeometry& nominal, const Sensors& sensors) {
  std::filesystem::create_directories(dir / "runs");
  std::ofstream robot(dir / "robot.yaml");
  robot.precision(10);
  robot << "model: diff_drive\nname: independent_dd\nwheels:\n"
        << "  - {name: right, radius_m: " << nominal.r_right_m << "}\n"
        << "  - {name: left, radius_m: " << nominal.r_left_m << "}\n"
        << "wheel_separation_m: " << nominal.separation_m << "\n"
        << "bounds:\n  radius_m: [0.036, 0.048]\n  wheel_separation_m: [0.17, 0.23]\n"
        << "encoder: {ticks_per_rev: " << sensors.ticks_per_rev << ", cumulative: true}\n";
  std::ofstream dataset(dir / "dataset.yaml");
  dataset << "robot: robot.yaml\nruns:\n";
  for (const LabelledRun& labelled : runs) {
    const std::string id = labelled.trajectory + "_" + std::to_string(labelled.repetition);
    dataset << "  - {id: " << id << ", trajectory: " << labelled.trajectory
            << ", repetition: " << labelled.repetition << ", encoders: runs/" << id
            << "_encoders.csv, ground_truth: runs/" << id << "_gt.csv}\n";
    std::ofstream enc(dir / "runs" / (id + "_encoders.csv"));
    enc.precision(10);
    enc << "t,ticks_right,ticks_left\n";
    const SimulatedRun& run = labelled.run;
    for (std::size_t k = 0; k < run.encoder_t_s.size(); ++k) {
      enc << run.encoder_t_s[k] << ',' << run.ticks_right[k] << ',' << run.ticks_left[k] << '\n';
    }
    std::ofstream gt(dir / "runs" / (id + "_gt.csv"));
    gt.precision(12);
    gt << "t,x,y,theta\n";
    for (std::size_t k = 0; k < run.mocap_t_s.size(); ++k) {
      gt << run.mocap_t_s[k] << ',' << run.mocap[k].x << ',' << run.mocap[k].y << ','
         << run.mocap[k].theta << '\n';
    }
  }
}

// The same for repetitions 1..N of one trajectory label.
inline void WriteDataSet(const std::filesystem::path& dir, const std::vector<SimulatedRun>& runs,
                         const DiffDriveGeometry& nominal, const Sensors& sensors,
                         const std::string& label = "drive") {
  std::vector<LabelledRun> labelled;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    labelled.push_back({label, static_cast<int>(i) + 1, runs[i]});
  }
  WriteLabelledDataSet(dir, labelled, nominal, sensors);
}

}  // namespace independent_sim
