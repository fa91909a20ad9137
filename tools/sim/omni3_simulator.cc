#include "tools/sim/omni3_simulator.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "odometry/parallel_for.h"

namespace fitcal::sim {

namespace {

// Portable random numbers: mt19937_64 is fully specified by the standard, the distributions on
// top of it are not, so they are written out here.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  double Gaussian() {  // Box-Muller
    double u1 = Uniform();
    while (u1 <= 0.0) u1 = Uniform();
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 engine_;
};

std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

void Validate(const Omni3SimulationOptions& o) {
  const auto fail = [](const char* what) {
    throw std::invalid_argument(std::string("simulation: ") + what);
  };
  if (o.repetitions < 1) fail("repetitions must be >= 1");
  if (o.trajectories.empty()) fail("no trajectories");
  if (!(o.encoder_period_s > 0.0)) fail("encoder_period_s must be > 0");
  if (!(o.encoder_jitter_s >= 0.0 && o.encoder_jitter_s < 0.5 * o.encoder_period_s)) {
    fail("encoder_jitter_s must be in [0, period/2)");
  }
  if (!(o.substep_s > 0.0 && o.substep_s <= o.encoder_jitter_s + o.encoder_period_s)) {
    fail("substep_s must be > 0 and not longer than an encoder period");
  }
  if (o.encoder_counts_per_rev < 1) fail("encoder_counts_per_rev must be >= 1");
  for (double e : o.wheel_eccentricity) {
    if (!(std::abs(e) < 0.5)) fail("wheel_eccentricity must be in (-0.5, 0.5)");
  }
  if (!(o.controller_time_constant_s > 0.0)) fail("controller_time_constant_s must be > 0");
  if (!(o.gt_period_min_s > 0.0 && o.gt_period_max_s >= o.gt_period_min_s)) {
    fail("ground-truth period must satisfy 0 < min <= max");
  }
  if (!(o.slip_sigma >= 0.0 && o.slip_correlation_time_s > 0.0)) fail("bad slip model");
  if (!(o.gt_position_sigma_m >= 0.0 && o.gt_heading_sigma_rad >= 0.0))
    fail("negative noise sigma");
  for (const MotionCommand& c : o.trajectories) {
    if (!(c.speed_m_s > 0.0 && c.distance_m > 0.0))
      fail("trajectory needs speed > 0 and distance > 0");
  }
}

SimulatedRun SimulateRun(const Omni3SimulationOptions& o, const MotionCommand& command,
                         int repetition, std::uint64_t stream) {
  Random rng(SplitMix(o.seed ^ SplitMix(stream)));
  const auto true_p = o.true_robot.ToArray();
  const auto commanded_p = o.commanded_robot.ToArray();
  const Eigen::Matrix3d m_inv_true = omni3::InverseKinematicMatrix(true_p.data());
  const Eigen::Vector3d target = omni3::WheelRatesForCommand(
      commanded_p.data(), command.speed_m_s, command.alpha_rad, command.omega_rad_s);

  const double h = o.substep_s;
  const double move_begin = o.rest_before_s;
  const double move_end = move_begin + command.distance_m / command.speed_m_s;
  const double t_end = move_end + o.rest_after_s;
  const double lag = 1.0 - std::exp(-h / o.controller_time_constant_s);
  const double slip_decay = std::exp(-h / o.slip_correlation_time_s);
  const double slip_kick = o.slip_sigma * std::sqrt(1.0 - slip_decay * slip_decay);
  const double count_rad = 2.0 * M_PI / o.encoder_counts_per_rev;

  SimulatedRun out;
  RunLog& log = out.log;
  char id[64];
  std::snprintf(id, sizeof id, "%s-rep%02d", command.label.c_str(), repetition);
  log.id = id;
  log.trajectory = command.label;
  log.repetition = repetition;

  Pose2d pose{rng.Uniform(-o.start_position_range_m, o.start_position_range_m),
              rng.Uniform(-o.start_position_range_m, o.start_position_range_m),
              rng.Uniform(-M_PI, M_PI)};
  Eigen::Vector3d wheel_rate = Eigen::Vector3d::Zero();
  Eigen::Vector3d wheel_angle = Eigen::Vector3d::Zero();
  Eigen::Vector3d slip(o.slip_sigma * rng.Gaussian(), o.slip_sigma * rng.Gaussian(),
                       o.slip_sigma * rng.Gaussian());
  Eigen::Vector3d wheel_start = Eigen::Vector3d::Zero();  // absolute angle at t = 0
  if (o.random_wheel_start_angle) {
    Random wheel_rng(SplitMix(o.seed ^ SplitMix(stream) ^ 0x57686565ull));
    log.encoders.start_angle_rad.resize(3);
    for (int i = 0; i < 3; ++i) {
      wheel_start[i] = wheel_rng.Uniform(0.0, 2.0 * M_PI);
      log.encoders.start_angle_rad[i] = wheel_start[i];
    }
  }
  const bool eccentric = o.wheel_eccentricity != std::array<double, 3>{};

  // Injected effects (see the header); the time offset only moves ground-truth stamps.
  std::vector<effects::ActiveEffect<double>> active;
  for (const auto& e : o.injected_effects) active.push_back({e.id, e.value.data()});
  const auto& table = effects::EffectOpsTable<double>();
  const double latency_s = effects::TotalLatency(active);
  const bool injecting = !active.empty() || static_cast<bool>(o.injection_hook);

  // Sample schedules: encoders every period with jitter; ground truth at irregular intervals,
  // starting within one period after the encoders.
  const auto encoder_time = [&](int k) {
    return k * o.encoder_period_s +
           (k == 0 ? 0.0 : rng.Uniform(-o.encoder_jitter_s, o.encoder_jitter_s));
  };
  int next_encoder = 0;
  double next_encoder_t = encoder_time(0);
  double next_gt_t = rng.Uniform(0.0, o.gt_period_max_s);
  std::int64_t last_counts[3] = {0, 0, 0};
  double last_encoder_t = 0.0;

  const auto latch = [&](double t, const Eigen::Vector3d& angle, const Pose2d& p) {
    // Encoder: counts latched at t.
    while (next_encoder_t <= t + 1e-12 && next_encoder_t <= t_end + 1e-12) {
      std::int64_t counts[3];
      for (int i = 0; i < 3; ++i)
        counts[i] = static_cast<std::int64_t>(std::floor(angle[i] / count_rad));
      if (next_encoder > 0) {
        const double dt = t - last_encoder_t;
        double values[3];
        for (int i = 0; i < 3; ++i) values[i] = (counts[i] - last_counts[i]) * count_rad / dt;
        log.encoders.samples.push_back(dt, values);
      }
      log.encoders.t_s.push_back(t);
      for (int i = 0; i < 3; ++i) last_counts[i] = counts[i];
      last_encoder_t = t;
      ++next_encoder;
      next_encoder_t = encoder_time(next_encoder);
      if (next_encoder_t <= t) next_encoder_t = t + h;  // jitter never reorders samples
    }
    while (next_gt_t <= t + 1e-12) {
      log.ground_truth.t_s.push_back(t + latency_s);
      log.ground_truth.world_T_robot.push_back(
          Pose2d{p.x + o.gt_position_sigma_m * rng.Gaussian(),
                 p.y + o.gt_position_sigma_m * rng.Gaussian(),
                 WrapAngle(p.theta + o.gt_heading_sigma_rad * rng.Gaussian())});
      next_gt_t += rng.Uniform(o.gt_period_min_s, o.gt_period_max_s);
    }
  };

  const long steps = static_cast<long>(std::ceil(t_end / h));
  latch(0.0, wheel_angle, pose);
  for (long n = 0; n < steps; ++n) {
    const double t = n * h;
    const double t_mid = t + 0.5 * h;
    const Eigen::Vector3d goal =
        (t_mid >= move_begin && t_mid < move_end) ? target : Eigen::Vector3d::Zero();
    wheel_rate += lag * (goal - wheel_rate);
    for (int i = 0; i < 3; ++i) slip[i] = slip_decay * slip[i] + slip_kick * rng.Gaussian();
    const Eigen::Vector3d wheel_accel = (goal - wheel_rate) * (lag / (1.0 - lag) / h);
    Eigen::Vector3d contact = wheel_rate.cwiseProduct(Eigen::Vector3d::Ones() + slip);
    for (int i = 0; eccentric && i < 3; ++i) {
      const double angle_mid = wheel_start[i] + wheel_angle[i] + 0.5 * h * wheel_rate[i];
      contact[i] *= 1.0 + o.wheel_eccentricity[i] * std::cos(angle_mid);
    }
    Eigen::Vector3d v;
    Eigen::Vector2d v_world = Eigen::Vector2d::Zero();
    if (injecting) {
      effects::SampleContext c;
      c.t_s = t;
      c.dt_s = h;
      for (int i = 0; i < 3; ++i) {
        c.angle_rad[i] = wheel_angle[i];
        c.derivative[i] = wheel_accel[i];
        c.moving = c.moving || std::abs(wheel_rate[i]) > effects::kMovingRateRadS;
      }
      effects::ApplyRateEffects(active, c, contact.data());
      v = m_inv_true * contact;
      for (const auto& e : active) {
        const auto& ops = table[static_cast<int>(e.id)];
        if (ops.body != nullptr) ops.body(e.q, c, v.data());
        if (ops.world != nullptr) ops.world(e.q, c, v_world.data());
      }
      if (o.injection_hook) {
        Omni3SimulationOptions::InjectionState state;
        state.t_s = t;
        state.time_since_motion_s = t_mid >= move_begin ? t - move_begin : -1.0;
        state.wheel_rate = wheel_rate;
        state.wheel_angle_rad = wheel_angle;
        state.pose = pose;
        o.injection_hook(state, &contact, &v, &v_world);
      }
    } else {
      v = m_inv_true * contact;
    }
    const double heading_mid = pose.theta + 0.5 * h * v[2];
    pose.x += h * (std::cos(heading_mid) * v[0] - std::sin(heading_mid) * v[1] + v_world[0]);
    pose.y += h * (std::sin(heading_mid) * v[0] + std::cos(heading_mid) * v[1] + v_world[1]);
    pose.theta += h * v[2];
    wheel_angle += h * wheel_rate;
    latch((n + 1) * h, wheel_angle, pose);
  }
  out.true_final_pose = pose;
  return out;
}

}  // namespace

Omni3SimulationOptions NoiseFreeSimulationOptions() {
  Omni3SimulationOptions options;
  options.repetitions = 1;
  options.gt_position_sigma_m = 0.0;
  options.gt_heading_sigma_rad = 0.0;
  options.slip_sigma = 0.0;
  options.encoder_counts_per_rev = 1 << 22;
  options.encoder_jitter_s = 0.0;
  return options;
}

std::vector<SimulatedRun> SimulateOmni3(const Omni3SimulationOptions& options) {
  Validate(options);
  const std::size_t per_rep = options.trajectories.size();
  std::vector<SimulatedRun> runs(per_rep * static_cast<std::size_t>(options.repetitions));
  ParallelFor(runs.size(), 0, [&](std::size_t i) {
    const int repetition = static_cast<int>(i / per_rep) + 1;
    runs[i] = SimulateRun(options, options.trajectories[i % per_rep], repetition, i);
  });
  return runs;
}

}  // namespace fitcal::sim
