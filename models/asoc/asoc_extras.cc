#include "models/asoc/asoc_extras.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "models/asoc/asoc_robot_model.h"
#include "models/asoc/asoc_tables.h"

namespace fitcal {

namespace asoc {

namespace {

// Portable draws: mt19937_64's output is fixed by the standard, std:: distributions are not.
double Uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

// State: castor angles theta_i (body-relative), then the wheel angles, castor by castor.
constexpr int kStateSize = 3 * kNumCastors;
using State = std::array<double, kStateSize>;

class CastorDynamics : public ChannelDynamics {
 public:
  CastorDynamics(const Vehicle& truth, const std::array<double, kNumCastors>& theta0,
                 double pivot_quantum_rad)
      : truth_(truth), quantum_(pivot_quantum_rad) {
    for (int i = 0; i < kNumCastors; ++i) state_[i] = theta0[i];
  }

  // RK4 over each half step; the angle channels are the castors' at the middle (header).
  void Step(const Twist& v, double dt_s, double* values) override {
    const State start = state_;
    Rk4(v, 0.5 * dt_s);
    for (int i = 0; i < kNumCastors; ++i) {
      values[i * kChannelsPerCastor + kPivotChannel] = Gamma(i);
    }
    Rk4(v, 0.5 * dt_s);
    for (int i = 0; i < kNumCastors; ++i) {
      for (int k = 0; k < 2; ++k) {
        const int w = kNumCastors + 2 * i + k;
        values[i * kChannelsPerCastor + kWheelAChannel + k] = (state_[w] - start[w]) / dt_s;
      }
    }
  }

  // The absolute encoder rounds its reading to its step (none when 0).
  void Read(double* values) const override {
    for (int i = 0; i < kNumCastors; ++i) {
      const double gamma = Gamma(i);
      values[i * kChannelsPerCastor + kPivotChannel] =
          quantum_ > 0.0 ? std::round(gamma / quantum_) * quantum_ : gamma;
    }
  }

 private:
  double Gamma(int i) const { return state_[i] + truth_.castors[i].encoder_bias_rad; }

  // theta_dot_i = (v_pivot . c2) / r_c - omega in the body frame; the wheels roll as the pivot
  // moves (asoc_model.h).
  State Derivative(const State& s, const Twist& v) const {
    State d{};
    for (int i = 0; i < kNumCastors; ++i) {
      const auto [bx, by] = PivotVelocity(v, truth_.pivots[i]);
      const double c = std::cos(s[i]), sn = std::sin(s[i]);
      const double along = c * bx + sn * by;
      const double lateral = -sn * bx + c * by;
      d[i] = lateral / truth_.castors[i].offset_m - v.omega_rad_s;
      const auto rates = WheelRatesFromPivotMotion(truth_.castors[i], along, lateral);
      d[kNumCastors + 2 * i] = rates[0];
      d[kNumCastors + 2 * i + 1] = rates[1];
    }
    return d;
  }

  void Rk4(const Twist& v, double h) {
    const auto plus = [](const State& s, const State& d, double f) {
      State out = s;
      for (int k = 0; k < kStateSize; ++k) out[k] += f * d[k];
      return out;
    };
    const State k1 = Derivative(state_, v);
    const State k2 = Derivative(plus(state_, k1, 0.5 * h), v);
    const State k3 = Derivative(plus(state_, k2, 0.5 * h), v);
    const State k4 = Derivative(plus(state_, k3, h), v);
    for (int k = 0; k < kStateSize; ++k) {
      state_[k] += h / 6.0 * (k1[k] + 2.0 * k2[k] + 2.0 * k3[k] + k4[k]);
    }
  }

  Vehicle truth_;
  double quantum_;
  State state_{};
};

const AsocModel& AsAsoc(const RobotModelInterface& model) {
  const auto* asoc = dynamic_cast<const AsocModel*>(&model);
  if (asoc == nullptr) throw std::invalid_argument("not an asoc robot: " + model.robot().model);
  return *asoc;
}

// The model's vehicle (its pivot layout) with the castor parameters p.
Vehicle VehicleOf(const RobotModelInterface& model, const std::vector<double>& p) {
  Vehicle v = AsAsoc(model).asoc().nominal;
  v.SetFromArray(p.data());
  return v;
}

}  // namespace

ScenarioRecorder PrototypeRecorder() {
  ScenarioRecorder r;
  r.encoder_period_s = kPrototypeSamplePeriodS;
  r.ground_truth_period_s = kPrototypeSamplePeriodS;
  r.ticks_per_rev = kPrototypeWheelTicksPerRev;
  r.wheel_rate_sigma_rad_s = 0.0;
  r.angle_sigma_rad = 0.0;  // the pivots' own step (pivot_resolution_deg) is their error
  r.gt_position_sigma_m = 0.0;
  r.gt_heading_sigma_rad = 0.0;
  r.start_position_range_m = 0.0;
  return r;
}

Vehicle DrawVehicle(const Vehicle& nominal, const ParameterSpread& spread, std::mt19937_64& rng) {
  Vehicle v = nominal;
  for (CastorParameters& c : v.castors) {
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

std::array<double, kNumCastors> SteadyCastorAngles(const Vehicle& truth, const Twist& twist,
                                                   double rest_angle_rad) {
  std::array<double, kNumCastors> theta{};
  for (int i = 0; i < kNumCastors; ++i) {
    const std::array<double, 2> pivot_velocity = PivotVelocity(twist, truth.pivots[i]);
    double along = 0.0;
    if (std::hypot(pivot_velocity[0], pivot_velocity[1]) < 1e-12 ||
        !TrailingCastorAngle(pivot_velocity, truth.castors[i].offset_m, twist.omega_rad_s,
                             &theta[i], &along)) {
      theta[i] = rest_angle_rad;
    }
  }
  return theta;
}

std::unique_ptr<ChannelDynamics> MakeCastorDynamics(const Vehicle& truth,
                                                    const std::array<double, kNumCastors>& theta0,
                                                    double pivot_quantum_rad) {
  return std::make_unique<CastorDynamics>(truth, theta0, pivot_quantum_rad);
}

sim::TrajectorySpec ExcursionTrajectory(int repetition, int num_segments) {
  std::mt19937_64 rng(0x4153'4f43'0000'0000ull + static_cast<std::uint64_t>(repetition));
  std::vector<sim::TwistSegment> segments;
  for (int k = 0; k < num_segments; ++k) {
    const double speed = Uniform(rng, 0.0, 0.4);
    const double direction = Uniform(rng, -M_PI, M_PI);
    const double omega = Uniform(rng, -0.6, 0.6);
    const Twist twist{speed * std::cos(direction), speed * std::sin(direction), omega};
    segments.push_back({twist, Uniform(rng, 2.0, 5.0)});
  }
  return {"excursion", repetition, std::move(segments)};
}

std::vector<sim::TrajectorySpec> HoldTrajectories(const Vehicle& nominal) {
  constexpr double kAngleRad = 1.5 * M_PI, kRateRadS = 0.4;
  std::vector<sim::TrajectorySpec> out;
  for (int held = 0; held < kNumCastors; ++held) {
    for (int direction : {-1, +1}) {
      // The held pivot stays still: v_origin + omega x p_held = 0.
      const double w = direction * kRateRadS;
      const PivotPosition& p = nominal.pivots[held];
      out.push_back({"hold_" + std::to_string(held + 1) + (direction < 0 ? "_cw" : "_ccw"), 1,
                     {{{w * p.y_m(), -w * p.x_m(), w}, kAngleRad / kRateRadS}}});
    }
  }
  return out;
}

std::vector<sim::TrajectorySpec> UmbmarkTrajectories(int per_direction, int first_repetition) {
  constexpr double kSideM = 1.5, kTurnRateRadS = 0.5, kStopS = 0.4;  // a ramp down and up
  std::vector<sim::TrajectorySpec> out;
  for (int direction : {-1, +1}) {
    for (int k = 0; k < per_direction; ++k) {
      const double speed_m_s = 0.3 * (1.0 + 0.02 * k);
      std::vector<sim::TwistSegment> square;
      // Borenstein's square: drive a side, stop, turn in place, stop.
      for (int leg = 0; leg < 4; ++leg) {
        square.push_back({{speed_m_s, 0.0, 0.0}, kSideM / speed_m_s});
        square.push_back({{}, kStopS});
        square.push_back({{0.0, 0.0, direction * kTurnRateRadS}, 0.5 * M_PI / kTurnRateRadS});
        if (leg < 3) square.push_back({{}, kStopS});
      }
      out.push_back({direction < 0 ? "umbmark_cw" : "umbmark_ccw", first_repetition + k,
                     std::move(square)});
    }
  }
  return out;
}

}  // namespace asoc

ModelExtras AsocExtras() {
  ModelExtras extras;
  extras.scenario.trajectories = [](const RobotModelInterface& nominal, const std::vector<double>&,
                                    int repetitions) {
    std::vector<sim::TrajectorySpec> out =
        asoc::HoldTrajectories(asoc::AsAsoc(nominal).asoc().nominal);
    for (sim::TrajectorySpec& spec : asoc::UmbmarkTrajectories(5, 6)) out.push_back(spec);
    for (int k = 1; k <= repetitions; ++k) out.push_back(asoc::ExcursionTrajectory(k));
    return out;
  };
  extras.closed_forms = {{"asoc-geometric", [](const RobotModelInterface& model,
                                                const std::vector<AlignedRun>& training) {
                            return asoc::AsAsoc(model).Geometric(training);
                          }}};
  extras.paper_tables = asoc::DoebblerPaperTables();
  extras.scenario.default_repetitions = 5;
  extras.scenario.repetition_unit = "excursions";  // the holds and squares are always driven
  extras.scenario.recorder = asoc::PrototypeRecorder();
  extras.scenario.default_truth = [](const Robot& nominal, std::uint64_t seed) {
    asoc::Vehicle v;
    v.SetFromArray(nominal.nominal.data());
    std::mt19937_64 rng(SplitMix(seed));
    const auto p = asoc::DrawVehicle(v, asoc::ParameterSpread{}, rng).ToArray();
    return std::vector<double>(p.begin(), p.end());
  };
  extras.scenario.dynamics = [](const RobotModelInterface& model, const std::vector<double>& truth,
                                const sim::TrajectorySpec& spec) {
    const asoc::Vehicle vehicle = asoc::VehicleOf(model, truth);
    const Twist first = spec.segments.empty() ? Twist{} : spec.segments.front().twist;
    return asoc::MakeCastorDynamics(vehicle, asoc::SteadyCastorAngles(vehicle, first),
                                    asoc::AsAsoc(model).asoc().pivot_resolution_rad);
  };
  return extras;
}

}  // namespace fitcal
