#pragma once
// The independent simulator's other two robots (see everyday_drive_sim.h for the diff drive and
// the shared sensors): a tricycle and a three-wheeled omni robot. Like the diff drive, written
// from the physics, sharing no code with fitcal (standard library and everyday_drive_sim.h only).
//
// Tricycle (a forklift or tugger): a steered, driven wheel ahead of a passive rear axle.
// - Reference point: the rear axle's centre, which the motion capture tracks.
// - The steered wheel's contact point sits wheelbase_m ahead of it on the body x axis. The rear
//   wheels roll without side slip, so the rear axle's centre moves along the body x axis; the
//   front contact point moves along the wheel's plane at angle psi (counter-clockwise from body
//   x). Rigid body: the front point's velocity is (vx, omega L), which must be u (cos psi,
//   sin psi), so vx = u cos psi, omega = u sin psi / L.
// - The steering actuator follows the commanded wheel angle with a first-order lag; the column's
//   absolute encoder reads (psi - offset) / gain, quantised to its counts per turn.
// - The traction wheel: motor lag, traction slip and wandering slip as the diff drive's wheels.
//
// Three-wheeled omni robot (Palacin et al. 2022, their Fig. 2, derived here from the rigid body):
// wheel i sits at distance R_i from the centre at angle delta_i and rolls along the tangent
// (-sin delta_i, cos delta_i); its rollers slide freely along the radius. The contact point's
// velocity (vx - omega R_i sin delta_i, vy + omega R_i cos delta_i) projected on the tangent is
// the wheel's ground speed u_i = -sin(delta_i) vx + cos(delta_i) vy + R_i omega; three wheels
// fix the twist (a 3x3 solve by Cramer's rule). Each wheel: motor lag, traction and wandering
// slip as above.

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "tests/independent_sim/everyday_drive_sim.h"

namespace independent_sim {

// ---------------------------------------------------------------------------------------------
// Shared pieces of the two robots.

// A body twist held for a duration (vy only for the omni robot; the tricycle takes the steered
// wheel's angle in `psi_rad` and its ground speed in `v_m_s`).
struct TwistCommand {
  double v_m_s = 0.0, vy_m_s = 0.0, omega_rad_s = 0.0, psi_rad = 0.0, duration_s = 0.0;
};

namespace detail {

// One driven wheel through an integration step: the motor follows `target_rate` with the lag,
// the contact point moves at rim speed (1 - slip), slip = traction part + wandering part (the
// diff drive's ContactPhysics, no gear play). Returns the contact point's ground speed.
inline double DriveWheel(const ContactPhysics& physics, double radius_m, double target_rate,
                         double step_s, double walk_decay, double walk_kick,
                         std::normal_distribution<double>& normal, std::mt19937_64& rng,
                         WheelState* w) {
  const double previous = w->motor_rate;
  w->motor_rate += (target_rate - w->motor_rate) * step_s / physics.motor_tau_s;
  w->motor_angle += w->motor_rate * step_s;
  const double acceleration_m_s2 = radius_m * (w->motor_rate - previous) / step_s;
  w->walk = walk_decay * w->walk + walk_kick * normal(rng);
  const double slip = physics.traction_slip_per_m_s2 * acceleration_m_s2 + w->walk;
  return radius_m * w->motor_rate * (1.0 - slip);
}

// The body's motion over a step under a constant twist (vx, vy, omega in the body frame): the
// SE(2) exponential, so turns are exact arcs.
inline void ExactStep(double vx, double vy, double omega, double step_s, Pose* pose) {
  const double a = omega * step_s;
  double fx = 1.0, fy = 0.0;  // V(a) = [[sin a / a, -(1 - cos a) / a], [(1 - cos a) / a, ...]]
  if (std::abs(a) > 1e-9) {
    fx = std::sin(a) / a;
    fy = (1.0 - std::cos(a)) / a;
  }
  const double dx = (fx * vx - fy * vy) * step_s, dy = (fy * vx + fx * vy) * step_s;
  const double c = std::cos(pose->theta), s = std::sin(pose->theta);
  pose->x += c * dx - s * dy;
  pose->y += s * dx + c * dy;
  pose->theta += a;
}

inline Pose NoisyPose(const Pose& truth, const Sensors& sensors,
                      std::normal_distribution<double>& normal, std::mt19937_64& rng) {
  return {truth.x + sensors.mocap_xy_sigma_m * normal(rng),
          truth.y + sensors.mocap_xy_sigma_m * normal(rng),
          truth.theta + sensors.mocap_theta_sigma_rad * normal(rng)};
}

inline std::int64_t Ticks(double motor_angle_rad, const Sensors& sensors) {
  return static_cast<std::int64_t>(
      std::floor(sensors.encoder_scale * motor_angle_rad / kTwoPi * sensors.ticks_per_rev));
}

}  // namespace detail

// A run of either robot: encoder columns (cumulative ticks of each driven wheel; the tricycle
// adds its steering column's reading in radians) and the noisy motion capture.
struct MultiChannelRun {
  std::vector<double> encoder_t_s;
  std::vector<std::vector<std::int64_t>> ticks;  // per sample, per wheel
  std::vector<double> steering_rad;              // tricycle only: the column's reading
  std::vector<double> mocap_t_s;
  std::vector<Pose> mocap;
  double path_m = 0.0;
};

namespace detail {

// The motion capture's samples due by time t (one every mocap_period_s from *next_mocap), each the
// true pose with its noise; both robots record through it.
inline void RecordMocapUntil(double t, const Pose& pose, const Sensors& sensors,
                             std::normal_distribution<double>& normal, std::mt19937_64& rng,
                             double* next_mocap, MultiChannelRun* run) {
  while (t >= *next_mocap - 1e-12) {
    run->mocap_t_s.push_back(*next_mocap);
    run->mocap.push_back(NoisyPose(pose, sensors, normal, rng));
    *next_mocap += sensors.mocap_period_s;
  }
}

}  // namespace detail

// ---------------------------------------------------------------------------------------------
// Tricycle.

struct TricycleGeometry {
  double radius_m = 0.0357;
  double wheelbase_m = 0.180;
  double steering_offset_rad = 0.0175;  // 1 deg
  double steering_gain = 0.97;          // wheel angle = gain * column angle + offset
};

struct SteeringActuator {
  double tau_s = 0.15;
  // The column's absolute encoder, 14 bits by default. At 12 bits the straight-ahead reading's
  // rounding (the same count on every straight) biases the fitted offset by a constant: a
  // resolution limit, not noise, which fitcal's sigmas hold since the readings' resolution is
  // measured (docs/everyday_driving.md, "Sigmas that cover").
  int counts_per_rev = 16384;
};

// Everyday driving of a tricycle: straights, arcs of 0.4-2 m radius either way, and sharp turns
// with the wheel at 50-80 deg (a forklift turning round in an aisle), stops between them, until
// the rear axle's path reaches length_m. Every command drives forwards at speed_m_s (the
// traction wheel's ground speed).
inline std::vector<TwistCommand> TricycleCommands(const TricycleGeometry& g, const Drive& drive,
                                                  std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<TwistCommand> out;
  double path = 0.0;
  while (path < drive.length_m) {
    const double pick = u(rng);
    const double sense = u(rng) < 0.5 ? -1.0 : 1.0;
    double psi = 0.0, length = 0.0;  // rear-axle path of the command
    if (pick < 0.35) {
      length = 1.0 + 2.0 * u(rng);
    } else if (pick < 0.8) {
      const double radius = 0.4 + 1.6 * u(rng);
      psi = sense * std::atan(g.wheelbase_m / radius);
      length = (0.25 + 0.75 * u(rng)) * kTwoPi / 2.0 * radius;
    } else {
      psi = sense * (50.0 + 30.0 * u(rng)) * kTwoPi / 360.0;
      const double turn_rad = (0.5 + 0.5 * u(rng)) * kTwoPi / 2.0;
      length = turn_rad * g.wheelbase_m / std::tan(std::abs(psi));
    }
    // Rear-axle speed is u cos psi.
    out.push_back({drive.speed_m_s, 0.0, 0.0, psi, length / (drive.speed_m_s * std::cos(psi))});
    path += length;
    if (u(rng) < 0.4) out.push_back({0.0, 0.0, 0.0, psi, 0.6});
  }
  out.push_back({0.0, 0.0, 0.0, 0.0, 1.0});
  return out;
}

inline MultiChannelRun SimulateTricycle(const TricycleGeometry& g, const ContactPhysics& physics,
                                        const SteeringActuator& steering, const Sensors& sensors,
                                        const Drive& drive, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::vector<TwistCommand> commands = TricycleCommands(g, drive, rng);
  std::normal_distribution<double> normal(0.0, 1.0);
  constexpr double kStepS = 0.001;
  const double walk_decay = std::exp(-kStepS / physics.walk_tau_s);
  const double walk_kick = physics.walk_sigma * std::sqrt(1.0 - walk_decay * walk_decay);
  detail::WheelState wheel;
  double psi = 0.0;  // the wheel's true angle
  Pose pose;
  MultiChannelRun run;
  double t = 0.0, next_encoder = 0.0, next_mocap = 0.0;
  const auto record = [&]() {
    while (t >= next_encoder - 1e-12) {
      run.encoder_t_s.push_back(next_encoder);
      run.ticks.push_back({detail::Ticks(wheel.motor_angle, sensors)});
      const double column = (psi - g.steering_offset_rad) / g.steering_gain;
      const double count = std::round(column / kTwoPi * steering.counts_per_rev);
      run.steering_rad.push_back(count * kTwoPi / steering.counts_per_rev);
      next_encoder += sensors.encoder_period_s;
    }
    detail::RecordMocapUntil(t, pose, sensors, normal, rng, &next_mocap, &run);
  };
  record();
  for (const TwistCommand& c : commands) {
    const int steps = static_cast<int>(std::round(c.duration_s / kStepS));
    for (int i = 0; i < steps; ++i) {
      psi += (c.psi_rad - psi) * kStepS / steering.tau_s;
      const double ground = detail::DriveWheel(physics, g.radius_m, c.v_m_s / g.radius_m, kStepS,
                                               walk_decay, walk_kick, normal, rng, &wheel);
      const double vx = ground * std::cos(psi), omega = ground * std::sin(psi) / g.wheelbase_m;
      detail::ExactStep(vx, 0.0, omega, kStepS, &pose);
      run.path_m += std::abs(vx) * kStepS;
      t += kStepS;
      record();
    }
  }
  return run;
}

// ---------------------------------------------------------------------------------------------
// Three-wheeled omni robot.

struct Omni3Geometry {
  std::array<double, 3> distance_m = {0.200, 0.192, 0.197};
  std::array<double, 3> radius_m = {0.150, 0.146, 0.149};
  std::array<double, 3> angle_rad = {1.0559, 3.1276, 5.2500};  // 60.5, 179.2, 300.8 deg
};

// Everyday driving of an omni robot: straights in any body direction (the heading held), arcs of
// 0.4-2 m radius, straights while the body turns, turns in place; stops between them.
inline std::vector<TwistCommand> Omni3Commands(const Drive& drive, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<TwistCommand> out;
  double path = 0.0;
  while (path < drive.length_m) {
    const double pick = u(rng);
    const double sense = u(rng) < 0.5 ? -1.0 : 1.0;
    const double direction = kTwoPi * u(rng);
    const double vx = drive.speed_m_s * std::cos(direction),
                 vy = drive.speed_m_s * std::sin(direction);
    if (pick < 0.3) {
      const double length = 1.0 + 2.0 * u(rng);
      out.push_back({vx, vy, 0.0, 0.0, length / drive.speed_m_s});
      path += length;
    } else if (pick < 0.6) {
      const double radius = 0.4 + 1.6 * u(rng);
      const double angle = (0.25 + 0.75 * u(rng)) * kTwoPi / 2.0;
      out.push_back(
          {vx, vy, sense * drive.speed_m_s / radius, 0.0, angle * radius / drive.speed_m_s});
      path += angle * radius;
    } else if (pick < 0.8) {
      const double length = 1.0 + 2.0 * u(rng);
      out.push_back({vx, vy, sense * 0.5 * drive.spin_rate_rad_s, 0.0, length / drive.speed_m_s});
      path += length;
    } else {
      const double angle = (0.5 + 0.5 * u(rng)) * kTwoPi / 2.0;
      out.push_back({0.0, 0.0, sense * drive.spin_rate_rad_s, 0.0, angle / drive.spin_rate_rad_s});
    }
    if (u(rng) < 0.4) out.push_back({0.0, 0.0, 0.0, 0.0, 0.6});
  }
  out.push_back({0.0, 0.0, 0.0, 0.0, 1.0});
  return out;
}

namespace detail {

// The twist (vx, vy, omega) whose tangential contact speeds are u: rows a_i = (-sin delta_i,
// cos delta_i, R_i), solved by Cramer's rule.
inline std::array<double, 3> TwistFromContactSpeeds(const Omni3Geometry& g,
                                                    const std::array<double, 3>& u) {
  double a[3][3];
  for (int i = 0; i < 3; ++i) {
    a[i][0] = -std::sin(g.angle_rad[i]);
    a[i][1] = std::cos(g.angle_rad[i]);
    a[i][2] = g.distance_m[i];
  }
  const auto det = [](const double m[3][3]) {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  };
  const double d = det(a);
  std::array<double, 3> out{};
  for (int col = 0; col < 3; ++col) {
    double m[3][3];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) m[i][j] = j == col ? u[i] : a[i][j];
    }
    out[col] = det(m) / d;
  }
  return out;
}

}  // namespace detail

inline MultiChannelRun SimulateOmni3(const Omni3Geometry& g, const ContactPhysics& physics,
                                     const Sensors& sensors, const Drive& drive,
                                     std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const std::vector<TwistCommand> commands = Omni3Commands(drive, rng);
  std::normal_distribution<double> normal(0.0, 1.0);
  constexpr double kStepS = 0.001;
  const double walk_decay = std::exp(-kStepS / physics.walk_tau_s);
  const double walk_kick = physics.walk_sigma * std::sqrt(1.0 - walk_decay * walk_decay);
  detail::WheelState wheel[3];
  Pose pose;
  MultiChannelRun run;
  double t = 0.0, next_encoder = 0.0, next_mocap = 0.0;
  const auto record = [&]() {
    while (t >= next_encoder - 1e-12) {
      run.encoder_t_s.push_back(next_encoder);
      run.ticks.push_back({detail::Ticks(wheel[0].motor_angle, sensors),
                           detail::Ticks(wheel[1].motor_angle, sensors),
                           detail::Ticks(wheel[2].motor_angle, sensors)});
      next_encoder += sensors.encoder_period_s;
    }
    detail::RecordMocapUntil(t, pose, sensors, normal, rng, &next_mocap, &run);
  };
  record();
  for (const TwistCommand& c : commands) {
    const int steps = static_cast<int>(std::round(c.duration_s / kStepS));
    for (int i = 0; i < steps; ++i) {
      std::array<double, 3> ground{};
      for (int w = 0; w < 3; ++w) {
        const double target =
            (-std::sin(g.angle_rad[w]) * c.v_m_s + std::cos(g.angle_rad[w]) * c.vy_m_s +
             g.distance_m[w] * c.omega_rad_s) /
            g.radius_m[w];
        ground[w] = detail::DriveWheel(physics, g.radius_m[w], target, kStepS, walk_decay,
                                       walk_kick, normal, rng, &wheel[w]);
      }
      const std::array<double, 3> twist = detail::TwistFromContactSpeeds(g, ground);
      detail::ExactStep(twist[0], twist[1], twist[2], kStepS, &pose);
      run.path_m += std::hypot(twist[0], twist[1]) * kStepS;
      t += kStepS;
      record();
    }
  }
  return run;
}

// ---------------------------------------------------------------------------------------------
// Writing a data set (docs/dataset-format.md): the robot YAML given as text (the nominal guess;
// the model's own schema), dataset.yaml, and per run an encoder CSV with `columns` (cumulative
// ticks per wheel, then the tricycle's `steering` in radians) and a ground-truth CSV. Runs are
// repetitions 1..N of the label "drive".
inline void WriteMultiChannelDataSet(const std::filesystem::path& dir,
                                     const std::vector<MultiChannelRun>& runs,
                                     const std::string& robot_yaml,
                                     const std::vector<std::string>& columns) {
  std::filesystem::create_directories(dir / "runs");
  std::ofstream(dir / "robot.yaml") << robot_yaml;
  std::ofstream dataset(dir / "dataset.yaml");
  dataset << "robot: robot.yaml\nruns:\n";
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const std::string id = "drive_" + std::to_string(i + 1);
    dataset << "  - {id: " << id << ", trajectory: drive, repetition: " << i + 1
            << ", encoders: runs/" << id << "_encoders.csv, ground_truth: runs/" << id
            << "_gt.csv}\n";
    const MultiChannelRun& run = runs[i];
    std::ofstream enc(dir / "runs" / (id + "_encoders.csv"));
    enc.precision(10);
    enc << 't';
    for (const std::string& c : columns) enc << ',' << c;
    enc << '\n';
    for (std::size_t k = 0; k < run.encoder_t_s.size(); ++k) {
      enc << run.encoder_t_s[k];
      for (std::int64_t ticks : run.ticks[k]) enc << ',' << ticks;
      if (!run.steering_rad.empty()) enc << ',' << run.steering_rad[k];
      enc << '\n';
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

}  // namespace independent_sim
