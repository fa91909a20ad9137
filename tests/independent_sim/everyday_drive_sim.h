#pragma once
// An independent simulator of a differential drive for the tests: it shares no code with
// fitcal's replay, models or simulator (it includes only the standard library), so a test that
// fits its data checks fitcal against physics fitcal was not written with.
//
// Physics, integrated in continuous time (1 kHz steps, each step an exact arc):
// - Motors follow the commanded wheel speeds with a first-order lag (tau_s): accelerations are
//   finite, so traction is too.
// - Gear train: the encoder sits on the motor shaft; the wheel follows the motor through a dead
//   band of backlash_rad (the wheel angle moves only when the motor pushes it at either edge).
// - Wheel-ground contact: the contact point moves at u = r phi_dot (1 - s), the longitudinal
//   slip s = k_a (r phi_ddot) + s_walk: proportional to the traction (the wheel's tangential
//   acceleration, positive when driving, negative when braking) plus a slowly wandering slip
//   (an Ornstein-Uhlenbeck random walk of stationary sigma walk_sigma and correlation time
//   walk_tau_s). Both are zero-mean, so the geometric radii stay the effective ones.
// - Body: v = (u_right + u_left) / 2, omega = (u_right - u_left) / b (rigid body, no lateral slip).
// Sensors:
// - Encoders: cumulative ticks floor(phi_motor / 2 pi * ticks_per_rev), every encoder_period_s.
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

struct Sensors {
  int ticks_per_rev = 4096;
  double encoder_period_s = 0.02;
  double mocap_period_s = 0.01;
  double mocap_xy_sigma_m = 0.001;
  double mocap_theta_sigma_rad = 0.0017;  // 0.1 deg
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

// One run from the origin (pose 0, 0, 0).
inline SimulatedRun SimulateDiffDrive(const DiffDriveGeometry& g, const ContactPhysics& physics,
                                      const Sensors& sensors, const Drive& drive,
                                      std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const std::vector<Command> commands = EverydayCommands(drive, rng);
  constexpr double kStepS = 0.001;
  const double r[2] = {g.r_right_m, g.r_left_m};
  double motor_rate[2] = {0.0, 0.0}, motor_angle[2] = {0.0, 0.0};
  double wheel_angle[2] = {0.0, 0.0}, wheel_rate[2] = {0.0, 0.0};
  double walk[2] = {0.0, 0.0};
  const double walk_decay = std::exp(-kStepS / physics.walk_tau_s);
  const double walk_kick = physics.walk_sigma * std::sqrt(1.0 - walk_decay * walk_decay);
  Pose pose;
  SimulatedRun run;
  double t = 0.0, next_encoder = 0.0, next_mocap = 0.0;
  const auto record = [&]() {
    while (t >= next_encoder - 1e-12) {
      run.encoder_t_s.push_back(next_encoder);
      run.ticks_right.push_back(static_cast<std::int64_t>(
          std::floor(motor_angle[0] / kTwoPi * sensors.ticks_per_rev)));
      run.ticks_left.push_back(static_cast<std::int64_t>(
          std::floor(motor_angle[1] / kTwoPi * sensors.ticks_per_rev)));
      run.true_pose_at_encoder.push_back(pose);
      next_encoder += sensors.encoder_period_s;
    }
    while (t >= next_mocap - 1e-12) {
      run.mocap_t_s.push_back(next_mocap);
      run.mocap.push_back({pose.x + sensors.mocap_xy_sigma_m * normal(rng),
                           pose.y + sensors.mocap_xy_sigma_m * normal(rng),
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
      double ground_speed[2];
      for (int w = 0; w < 2; ++w) {
        motor_rate[w] += (target[w] - motor_rate[w]) * kStepS / physics.motor_tau_s;
        motor_angle[w] += motor_rate[w] * kStepS;
        // Backlash: the wheel moves only when the motor pushes it at an edge of the dead band.
        const double half = physics.backlash_rad / 2.0;
        double next = wheel_angle[w];
        if (motor_angle[w] - next > half) next = motor_angle[w] - half;
        if (motor_angle[w] - next < -half) next = motor_angle[w] + half;
        const double rate = (next - wheel_angle[w]) / kStepS;
        const double acceleration_m_s2 = r[w] * (rate - wheel_rate[w]) / kStepS;
        wheel_angle[w] = next;
        wheel_rate[w] = rate;
        walk[w] = walk_decay * walk[w] + walk_kick * normal(rng);
        const double slip = physics.traction_slip_per_m_s2 * acceleration_m_s2 + walk[w];
        ground_speed[w] = r[w] * rate * (1.0 - slip);
      }
      const double v = 0.5 * (ground_speed[0] + ground_speed[1]);
      const double omega = (ground_speed[0] - ground_speed[1]) / g.separation_m;
      // Exact arc over the step.
      const double heading_mid = pose.theta + 0.5 * omega * kStepS;
      const double chord = std::abs(omega) > 1e-12
                               ? 2.0 * v / omega * std::sin(0.5 * omega * kStepS)
                               : v * kStepS;
      pose.x += chord * std::cos(heading_mid);
      pose.y += chord * std::sin(heading_mid);
      pose.theta += omega * kStepS;
      run.path_m += std::abs(v) * kStepS;
      t += kStepS;
      record();
    }
  }
  return run;
}

// Writes `runs` as a fitcal data set (docs/dataset-format.md) under `dir`: dataset.yaml, a
// diff_drive robot.yaml with `nominal` geometry and ticks encoders, one encoder CSV (cumulative
// ticks, right then left) and one ground-truth CSV per run. Runs are repetitions 1..N of one
// trajectory label.
inline void WriteDataSet(const std::filesystem::path& dir, const std::vector<SimulatedRun>& runs,
                         const DiffDriveGeometry& nominal, const Sensors& sensors,
                         const std::string& label = "drive") {
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
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const std::string id = label + "_" + std::to_string(i + 1);
    dataset << "  - {id: " << id << ", trajectory: " << label << ", repetition: " << i + 1
            << ", encoders: runs/" << id << "_encoders.csv, ground_truth: runs/" << id
            << "_gt.csv}\n";
    std::ofstream enc(dir / "runs" / (id + "_encoders.csv"));
    enc.precision(10);
    enc << "t,ticks_right,ticks_left\n";
    const SimulatedRun& run = runs[i];
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

}  // namespace independent_sim
