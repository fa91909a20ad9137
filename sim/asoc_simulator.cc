#include "sim/asoc_simulator.h"

#include <cmath>
#include <stdexcept>

namespace fitcal::sim {

namespace {

// Portable draws: mt19937_64's output is fixed by the standard, std:: distributions are not.
double Uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
}
double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * Uniform01(rng);
}
double Gaussian(std::mt19937_64& rng) {
  const double u1 = 1.0 - Uniform01(rng);  // (0, 1]
  const double u2 = Uniform01(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// Continuous state of the vehicle: body pose, absolute castor headings chi_i, wheel angles.
struct State {
  double x = 0.0, y = 0.0, psi = 0.0;
  double chi[asoc::kNumCastors] = {0.0, 0.0, 0.0};
  double wheel[asoc::kNumCastors][2] = {{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}};

  State Plus(const State& d, double h) const {
    State s = *this;
    s.x += h * d.x;
    s.y += h * d.y;
    s.psi += h * d.psi;
    for (int i = 0; i < asoc::kNumCastors; ++i) {
      s.chi[i] += h * d.chi[i];
      s.wheel[i][0] += h * d.wheel[i][0];
      s.wheel[i][1] += h * d.wheel[i][1];
    }
    return s;
  }
};

// Time derivative of the state for body-frame twist (vx, vy, omega) of the body origin.
State Derivative(const asoc::Vehicle& v, const State& s, double vx, double vy, double omega) {
  State d;
  const double c = std::cos(s.psi), sn = std::sin(s.psi);
  d.x = c * vx - sn * vy;
  d.y = sn * vx + c * vy;
  d.psi = omega;
  for (int i = 0; i < asoc::kNumCastors; ++i) {
    // Pivot velocity: body frame v + omega x p_i, rotated to the world.
    const double bx = vx - omega * v.pivots[i].y_m();
    const double by = vy + omega * v.pivots[i].x_m();
    const double wx = c * bx - sn * by, wy = sn * bx + c * by;
    const double cc = std::cos(s.chi[i]), sc = std::sin(s.chi[i]);
    const double along = cc * wx + sc * wy;
    const double lateral = -sc * wx + cc * wy;
    const asoc::CastorParameters& castor = v.castors[i];
    d.chi[i] = lateral / castor.offset_m;  // castor dynamics: no lateral slip
    const auto rates = asoc::WheelRatesFromPivotMotion(castor, along, lateral);
    d.wheel[i][0] = rates[0];
    d.wheel[i][1] = rates[1];
  }
  return d;
}

// Incremental encoder: whole counts of `quantum` (none when quantum is 0).
double Quantise(double value, double quantum) {
  return quantum > 0.0 ? std::floor(value / quantum) * quantum : value;
}

}  // namespace

asoc::Vehicle AsocPrototypeVehicle() {
  asoc::Vehicle v;
  for (int i = 0; i < asoc::kNumCastors; ++i) {
    v.pivots[i] = {0.30, 2.0 * M_PI * i / 3.0};  // phi_1 = 0 (Doebbler Sec. II-C)
    v.castors[i].offset_m = 0.08;
    v.castors[i].wheel_radius_m = {0.04, 0.04};
    v.castors[i].wheel_offset_m = {0.06, 0.06};
    v.castors[i].encoder_bias_rad = 0.0;
  }
  return v;
}

bool AsocSimulationOptions::IsValid(std::string* error) const {
  if (!(sample_period_s > 0.0) || substeps < 1) {
    *error = "sample_period_s must be > 0 and substeps >= 1";
    return false;
  }
  if (!(wheel_quantum_rad >= 0.0) || !(pivot_quantum_rad >= 0.0)) {
    *error = "encoder quanta must be >= 0";
    return false;
  }
  if (!(wheel_slip_sigma >= 0.0) || !(gt_position_sigma_m >= 0.0) ||
      !(gt_heading_sigma_rad >= 0.0)) {
    *error = "noise sigmas must be >= 0";
    return false;
  }
  for (const SlipEvent& e : slip_events) {
    if (e.castor < 0 || e.castor >= asoc::kNumCastors || e.wheel < 0 || e.wheel > 1) {
      *error = "slip event names a wheel that does not exist";
      return false;
    }
  }
  return true;
}

std::array<double, asoc::kNumCastors> SteadyCastorAngles(const asoc::Vehicle& truth,
                                                         const Segment& twist,
                                                         double rest_angle_rad) {
  std::array<double, asoc::kNumCastors> theta{};
  for (int i = 0; i < asoc::kNumCastors; ++i) {
    const double bx = twist.vx_m_s - twist.omega_rad_s * truth.pivots[i].y_m();
    const double by = twist.vy_m_s + twist.omega_rad_s * truth.pivots[i].x_m();
    const double speed = std::hypot(bx, by);
    const double lateral = truth.castors[i].offset_m * twist.omega_rad_s;  // chi_dot = omega
    if (speed < 1e-12 || std::abs(lateral) >= speed) {
      theta[i] = rest_angle_rad;
      continue;
    }
    // In the castor frame the pivot velocity is (u, w) = (sqrt(speed^2 - w^2), r_c omega):
    // c1 = the velocity direction turned back by atan2(w, u).
    theta[i] =
        std::atan2(by, bx) - std::atan2(lateral, std::sqrt(speed * speed - lateral * lateral));
  }
  return theta;
}

asoc::RunLog SimulateAsocRun(const asoc::Vehicle& truth, const std::vector<Segment>& segments,
                             const Pose2d& start,
                             const std::array<double, asoc::kNumCastors>& theta0,
                             const AsocSimulationOptions& options, std::mt19937_64& rng) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("AsocSimulationOptions: " + error);
  asoc::RunLog run;
  run.start_pose = start;
  State s;
  s.x = start.x;
  s.y = start.y;
  s.psi = start.theta;
  for (int i = 0; i < asoc::kNumCastors; ++i) s.chi[i] = start.theta + theta0[i];
  double encoder[asoc::kNumCastors][2] = {{0.0, 0.0}, {0.0, 0.0}, {0.0, 0.0}};
  double t = 0.0;
  auto record = [&]() {
    asoc::EncoderSample e;
    for (int i = 0; i < asoc::kNumCastors; ++i) {
      e.wheel_rad[i][0] = Quantise(encoder[i][0], options.wheel_quantum_rad);
      e.wheel_rad[i][1] = Quantise(encoder[i][1], options.wheel_quantum_rad);
      const double gamma = WrapAngle(s.chi[i] - s.psi + truth.castors[i].encoder_bias_rad) + M_PI;
      const double q = options.pivot_quantum_rad;
      // Absolute encoder on [0, 2 pi), reading rounded to its step.
      e.pivot_rad[i] = (q > 0.0 ? std::round(gamma / q) * q : gamma) - M_PI;
    }
    run.encoders.t_s.push_back(t);
    run.encoders.samples.push_back(e);
    Pose2d gt{s.x, s.y, s.psi};
    if (options.gt_position_sigma_m > 0.0) {
      gt.x += options.gt_position_sigma_m * Gaussian(rng);
      gt.y += options.gt_position_sigma_m * Gaussian(rng);
    }
    if (options.gt_heading_sigma_rad > 0.0)
      gt.theta += options.gt_heading_sigma_rad * Gaussian(rng);
    run.ground_truth.t_s.push_back(t);
    run.ground_truth.world_T_robot.push_back(gt);
  };
  record();
  const double h = options.sample_period_s / options.substeps;
  double segment_start = 0.0;
  for (const Segment& seg : segments) {
    const int samples =
        std::max(1, static_cast<int>(std::lround(seg.duration_s / options.sample_period_s)));
    const double duration = samples * options.sample_period_s;
    auto twist_at = [&](double t_abs, double* vx, double* vy, double* w) {
      const double f = 1.0 - std::cos(2.0 * M_PI * (t_abs - segment_start) / duration);
      *vx = seg.vx_m_s * f;
      *vy = seg.vy_m_s * f;
      *w = seg.omega_rad_s * f;
    };
    for (int k = 0; k < samples; ++k) {
      double before[asoc::kNumCastors][2];
      for (int i = 0; i < asoc::kNumCastors; ++i) {
        before[i][0] = s.wheel[i][0];
        before[i][1] = s.wheel[i][1];
      }
      for (int sub = 0; sub < options.substeps; ++sub) {
        double vx, vy, w;
        twist_at(t, &vx, &vy, &w);
        const State k1 = Derivative(truth, s, vx, vy, w);
        twist_at(t + 0.5 * h, &vx, &vy, &w);
        const State k2 = Derivative(truth, s.Plus(k1, 0.5 * h), vx, vy, w);
        const State k3 = Derivative(truth, s.Plus(k2, 0.5 * h), vx, vy, w);
        twist_at(t + h, &vx, &vy, &w);
        const State k4 = Derivative(truth, s.Plus(k3, h), vx, vy, w);
        s = s.Plus(k1, h / 6.0).Plus(k2, h / 3.0).Plus(k3, h / 3.0).Plus(k4, h / 6.0);
        t += h;
      }
      for (int i = 0; i < asoc::kNumCastors; ++i) {
        for (int j = 0; j < 2; ++j) {
          double scale = 1.0;
          if (options.wheel_slip_sigma > 0.0) scale += options.wheel_slip_sigma * Gaussian(rng);
          for (const SlipEvent& e : options.slip_events) {
            if (e.castor == i && e.wheel == j && t > e.t_begin_s && t <= e.t_end_s) {
              scale += e.extra_fraction;
            }
          }
          encoder[i][j] += scale * (s.wheel[i][j] - before[i][j]);
        }
      }
      record();
    }
    segment_start += duration;
    t = segment_start;  // removes the round-off of the substep sum
  }
  return run;
}

std::vector<Segment> UmbmarkSquare(int direction, double side_m, double speed_m_s,
                                   double turn_rate_rad_s) {
  std::vector<Segment> out;
  for (int leg = 0; leg < 4; ++leg) {
    out.push_back({side_m / speed_m_s, speed_m_s, 0.0, 0.0});
    out.push_back({0.5 * M_PI / turn_rate_rad_s, 0.0, 0.0, direction * turn_rate_rad_s});
  }
  return out;
}

std::vector<Segment> RotationAboutPivot(const asoc::Vehicle& nominal, int held, int direction,
                                        double angle_rad, double rate_rad_s) {
  const double w = direction * rate_rad_s;
  // The held pivot stays still: v_origin + omega x p_held = 0.
  return {
      {angle_rad / rate_rad_s, w * nominal.pivots[held].y_m(), -w * nominal.pivots[held].x_m(), w}};
}

std::vector<asoc::RunLog> SimulateCalibrationManoeuvre(const asoc::Vehicle& truth,
                                                       const AsocSimulationOptions& options,
                                                       std::mt19937_64& rng, double angle_rad) {
  std::vector<asoc::RunLog> runs;
  for (int held = 0; held < asoc::kNumCastors; ++held) {
    for (int direction : {-1, +1}) {
      const std::vector<Segment> segments = RotationAboutPivot(truth, held, direction, angle_rad);
      // The held castor points anywhere; the active ones are aligned for the rotation.
      const auto theta0 = SteadyCastorAngles(truth, segments.front(), 0.3 * held);
      asoc::RunLog run = SimulateAsocRun(truth, segments, Pose2d{}, theta0, options, rng);
      run.trajectory = "hold_" + std::to_string(held + 1) + (direction < 0 ? "_cw" : "_ccw");
      run.id = run.trajectory;
      run.repetition = 1;
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

std::vector<asoc::RunLog> SimulateUmbmark(const asoc::Vehicle& truth,
                                          const AsocSimulationOptions& options,
                                          std::mt19937_64& rng, int repetitions) {
  std::vector<asoc::RunLog> runs;
  for (int direction : {-1, +1}) {
    const std::vector<Segment> square = UmbmarkSquare(direction);
    const auto theta0 = SteadyCastorAngles(truth, square.front());
    for (int rep = 1; rep <= repetitions; ++rep) {
      asoc::RunLog run = SimulateAsocRun(truth, square, Pose2d{}, theta0, options, rng);
      run.trajectory = direction < 0 ? "umbmark_cw" : "umbmark_ccw";
      run.repetition = rep;
      run.id = run.trajectory + "-rep" + (rep < 10 ? "0" : "") + std::to_string(rep);
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

asoc::RunLog SimulateRandomExcursion(const asoc::Vehicle& truth,
                                     const AsocSimulationOptions& options, std::mt19937_64& rng,
                                     int num_segments) {
  std::vector<Segment> segments;
  for (int k = 0; k < num_segments; ++k) {
    const double speed = Uniform(rng, 0.0, 0.4);
    const double direction = Uniform(rng, -M_PI, M_PI);
    segments.push_back({Uniform(rng, 2.0, 5.0), speed * std::cos(direction),
                        speed * std::sin(direction), Uniform(rng, -0.6, 0.6)});
  }
  const auto theta0 = SteadyCastorAngles(truth, segments.front());
  return SimulateAsocRun(truth, segments, Pose2d{}, theta0, options, rng);
}

asoc::Vehicle DrawVehicle(const asoc::Vehicle& nominal, const ParameterSpread& spread,
                          std::mt19937_64& rng) {
  asoc::Vehicle v = nominal;
  for (asoc::CastorParameters& c : v.castors) {
    c.offset_m *= 1.0 + Uniform(rng, -spread.offset_fraction, spread.offset_fraction);
    for (int k = 0; k < 2; ++k) {
      c.wheel_radius_m[k] *=
          1.0 + Uniform(rng, -spread.wheel_radius_fraction, spread.wheel_radius_fraction);
      c.wheel_offset_m[k] *=
          1.0 + Uniform(rng, -spread.wheel_offset_fraction, spread.wheel_offset_fraction);
    }
    c.encoder_bias_rad += Uniform(rng, -spread.bias_range_rad, spread.bias_range_rad);
  }
  return v;
}

UmbmarkResult EvaluateUmbmark(const std::vector<asoc::RunLog>& runs, const asoc::Vehicle& estimate,
                              const asoc::OdometryOptions& odometry) {
  double sum[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
  int count[2] = {0, 0};
  for (const asoc::RunLog& run : runs) {
    const int dir = run.trajectory == "umbmark_cw" ? 0 : run.trajectory == "umbmark_ccw" ? 1 : -1;
    if (dir < 0) continue;
    const Pose2d start = run.start_pose.value_or(run.ground_truth.world_T_robot.front());
    const Pose2d est = asoc::RunOdometry(estimate, odometry, run.encoders, start);
    const Pose2d& truth = run.ground_truth.world_T_robot.back();
    sum[dir][0] += est.x - truth.x;
    sum[dir][1] += est.y - truth.y;
    ++count[dir];
  }
  if (count[0] == 0 || count[1] == 0) {
    throw std::invalid_argument("UMBmark needs umbmark_cw and umbmark_ccw runs");
  }
  UmbmarkResult r;
  r.r_cw_m = std::hypot(sum[0][0], sum[0][1]) / count[0];
  r.r_ccw_m = std::hypot(sum[1][0], sum[1][1]) / count[1];
  r.e_max_m = std::max(r.r_cw_m, r.r_ccw_m);
  return r;
}

}  // namespace fitcal::sim
