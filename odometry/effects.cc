#include "odometry/effects.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fitcal::effects {

const std::array<EffectInfo, kNumEffects>& EffectTable() {
  // Bounds are generous physical limits; "typical" is a realistic magnitude used by the
  // simulator's examples and the tests.
  static const std::array<EffectInfo, kNumEffects> table = {{
      // clang-format off
      // id, name,
      //  summary,
      //  equation,
      //  parameters: count, names, lower, upper, typical; identifiable,
      //  aliased_with, separating_runs[, parameters_required]
      {EffectId::kTimeOffset, "time_offset",
       "latency between the ground-truth and encoder clocks",
       "ground truth stamped t = pose at encoder time t - tau",
       1, {"latency_s", ""}, {-0.3, 0}, {0.3, 0}, {0.04, 0}, true,
       "nothing in the final pose of runs that end at rest",
       "none needed: the ground-truth track separates it"},
      {EffectId::kWheelSpeedSlip, "wheel_speed_slip",
       "effective radius falls with wheel speed",
       "w' = w (1 - k |w|)",
       1, {"slip_s_per_rad", ""}, {-0.05, 0}, {0.05, 0}, {0.01, 0}, true,
       "a common wheel-radius scale when every run has the same speed",
       "the flower at a second speed (e.g. 0.15 and 0.5 m/s)"},
      {EffectId::kDirectionRadius, "direction_radius",
       "wheel radius differs forward and backward",
       "w' = w (1 + a sign(w))",
       1, {"asymmetry", ""}, {-0.05, 0}, {0.05, 0}, {0.01, 0}, true,
       "the wheel radii when every wheel turns one way only",
       "runs in which each wheel turns both ways (the flower's R1-R12 do)"},
      {EffectId::kAccelerationSlip, "acceleration_slip",
       "wheels slip during start/stop transients (lost either way, and traction slip)",
       "w' = w (1 - c |dw/dt| - k sign(w) dw/dt)",
       2, {"slip_s2_per_rad", "traction_s2_per_rad"}, {-0.05, -0.05}, {0.05, 0.05},
       {0.015, 0}, true,
       "the radii when every run has the same speed profile",
       "runs of different length or acceleration (the flower at a second distance)",
       1},  // traction_s2_per_rad came later: older calibrations read it as 0
      {EffectId::kBacklash, "backlash",
       "gear play crossed again on every reversal of the wheel",
       "play operator of width beta on the wheel angle (the wheel follows once the play is "
       "taken up)",
       1, {"backlash_rad", ""}, {0.0, 0}, {0.3, 0}, {0.06, 0}, true,
       "the radii when every run has the same length",
       "runs of a second length (e.g. 0.5 m and 2 m)"},
      {EffectId::kFloorSlope, "floor_slope",
       "constant world-frame creep while moving",
       "pose' += dt (cx, cy) while moving",
       2, {"creep_x_m_s", "creep_y_m_s"}, {-0.05, -0.05}, {0.05, 0.05}, {0.006, -0.004}, true,
       "nothing when start headings vary",
       "runs with different start headings in the same place"},
      {EffectId::kYawRateSlip, "yaw_rate_slip",
       "body velocity slips with the yaw rate",
       "v' = v (1 - k |omega|)",
       1, {"slip_s_per_rad", ""}, {-1.0, 0}, {1.0, 0}, {0.1, 0}, true,
       "the distances R_i when every turning run has the same yaw rate",
       "the flower at a second yaw rate"},
      {EffectId::kOncePerRevolution, "once_per_revolution",
       "once-per-revolution encoder error (eccentric code wheel)",
       "w' = w (1 + a cos A + b sin A)",
       2, {"cos_amplitude", "sin_amplitude"}, {-0.1, -0.1}, {0.1, 0.1}, {0.03, -0.02}, true,
       "noise when runs are a whole number of revolutions",
       "runs of fractional wheel revolutions"},
      {EffectId::kEncoderClockScale, "encoder_clock_scale",
       "encoder clock runs fast or slow",
       "w' = w (1 + s)",
       1, {"scale_error", ""}, {-0.05, 0}, {0.05, 0}, {0.01, 0}, false,
       "a common scale of the wheel radii, exactly, on any data",
       "none: calibrate the clock against an external time reference"},
      {EffectId::kTranslationYawGain, "translation_yaw_gain",
       "yaw rate scaled by the robot-frame translation (omni-wheel contact points shift)",
       "omega' = omega (1 + g_x v_x + g_y v_y)",
       2, {"gain_x_s_per_m", "gain_y_s_per_m"}, {-0.5, -0.5}, {0.5, 0.5}, {0.08, -0.05}, true,
       "the distances R_i when every turning run translates the same way in the robot frame",
       "turning runs that translate in different robot-frame directions (e.g. circles driven "
       "with two different headings relative to the path) and with both yaw-rate signs"},
      {EffectId::kGroundTruthOffset, "ground_truth_offset",
       "tracked point offset from the kinematic centre (mocap/SLAM extrinsic)",
       "v' = v + omega x e  (== R_i - e_x cos delta_i - e_y sin delta_i)",
       2, {"offset_x_m", "offset_y_m"}, {-0.1, -0.1}, {0.1, 0.1}, {0.02, -0.015}, false,
       "the distances R_i, exactly (R_i' = R_i - e_x cos delta_i - e_y sin delta_i), on any data",
       "none from odometry: measure the offset (or hold the R_i at measured values); fitted R_i "
       "far from the measured ones with a common mean suggest it"},
      {EffectId::kSteeringScale, "steering_scale",
       "the steered wheel turns (1 + k) times the measured steering angle",
       "phi' = phi (1 + k)",
       1, {"scale", ""}, {-0.2, 0}, {0.2, 0}, {0.05, 0}, true,
       "the wheelbase when every run turns at one steering angle",
       "runs at two or more steering angles, turning both ways (circles of several radii)"},
      {EffectId::kSteeringLag, "steering_lag",
       "the measured steering angle lags the wheel's",
       "phi' = phi + tau dphi/dt",
       1, {"lag_s", ""}, {-0.5, 0}, {0.5, 0}, {0.1, 0}, true,
       "nothing while the steering angle is constant",
       "runs that change the steering angle while driving (squares, slaloms)"},
      {EffectId::kPivotYawGain, "pivot_yaw_gain",
       "the yaw rate grows as a wheel pair's turn tightens towards a pivot",
       "omega' = omega (1 + g |w_R - w_L| / (|w_R| + |w_L|))",
       1, {"gain", ""}, {-0.1, 0}, {0.1, 0}, {0.007, 0}, true,
       "the wheel separation when every run turns at one radius",
       "runs at two turning radii: circles and pivot turns (UMBmark squares)"},
      // clang-format on
  }};
  return table;
}

EffectId EffectIdFromName(const std::string& name) {
  for (const EffectInfo& info : EffectTable()) {
    if (name == info.name) return info.id;
  }
  std::string known;
  for (const EffectInfo& info : EffectTable())
    known += std::string(known.empty() ? "" : ", ") + info.name;
  throw std::invalid_argument("unknown effect '" + name + "' (known: " + known + ")");
}

namespace {

// Linear interpolation of a series (t, value) at `time`, clamped to its ends.
double InterpolateAt(const std::vector<double>& t, const std::vector<double>& v, double time) {
  if (time <= t.front()) return v.front();
  if (time >= t.back()) return v.back();
  const std::size_t j =
      static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin()) - 1;
  const double span = t[j + 1] - t[j];
  const double f = span > 0.0 ? (time - t[j]) / span : 0.0;
  return v[j] + f * (v[j + 1] - v[j]);
}

}  // namespace

std::vector<SampleContext> MakeSampleContexts(const EncoderSamples& samples, unsigned wheel_mask) {
  const std::size_t n = samples.size();
  const int channels = samples.num_channels();
  if (channels > kMaxEffectChannels) {
    throw std::invalid_argument("the effect replay handles at most " +
                                std::to_string(kMaxEffectChannels) + " channels, not " +
                                std::to_string(channels));
  }
  std::vector<SampleContext> out(n);
  if (n == 0) return out;
  // Sample boundary times, cumulative encoder angles (wheels) and the angle channels' values at
  // each interval's middle.
  std::vector<double> t(n + 1, 0.0), mid(n, 0.0);
  std::vector<std::vector<double>> cumulative(channels, std::vector<double>(n + 1, 0.0));
  std::vector<std::vector<double>> value(channels, std::vector<double>(n, 0.0));
  for (std::size_t k = 0; k < n; ++k) {
    t[k + 1] = t[k] + samples[k].dt_s;
    mid[k] = t[k] + 0.5 * samples[k].dt_s;
    for (int i = 0; i < channels; ++i) {
      cumulative[i][k + 1] = cumulative[i][k] + samples[k].value[i] * samples[k].dt_s;
      value[i][k] = samples[k].value[i];
    }
  }
  const double h = kAccelerationWindowS;
  for (std::size_t k = 0; k < n; ++k) {
    SampleContext& c = out[k];
    c.t_s = t[k];
    c.dt_s = samples[k].dt_s;
    c.num_channels = channels;
    c.wheel_mask = wheel_mask & ((1u << channels) - 1u);
    for (int i = 0; i < channels; ++i) {
      if (c.IsWheel(i)) {
        c.angle_rad[i] = cumulative[i][k];
        const auto angle_at = [&](double time) { return InterpolateAt(t, cumulative[i], time); };
        const double ahead = (angle_at(mid[k] + h) - angle_at(mid[k])) / h;
        const double behind = (angle_at(mid[k]) - angle_at(mid[k] - h)) / h;
        c.derivative[i] = (ahead - behind) / h;
        c.moving = c.moving || std::abs(samples[k].value[i]) > kMovingRateRadS;
      } else {
        c.angle_rad[i] = value[i][k];
        c.derivative[i] = n < 2 ? 0.0
                                : (InterpolateAt(mid, value[i], mid[k] + h) -
                                   InterpolateAt(mid, value[i], mid[k] - h)) /
                                      (2.0 * h);
      }
    }
    if (channels == 2 && c.wheel_mask == 0x3u) {
      const double a = samples[k].value[0], b = samples[k].value[1];
      const double sum = std::abs(a) + std::abs(b);
      c.turn_fraction = sum > 0.0 ? std::abs(a - b) / sum : 0.0;
    }
  }
  return out;
}

}  // namespace fitcal::effects
