#include "models/asoc/asoc_geometric.h"

#include <cmath>
#include <map>
#include <stdexcept>

#include "odometry/pose2.h"

namespace fitcal::asoc {

namespace {

// Circular mean of castor i's readings over the middle `fraction` of the run.
double SteadyAngle(const EncoderLog& log, int castor, double fraction) {
  const std::size_t n = log.samples.size();
  const std::size_t skip = static_cast<std::size_t>(std::floor(0.5 * (1.0 - fraction) * n));
  double s = 0.0, c = 0.0;
  for (std::size_t k = skip; k < n - skip; ++k) {
    s += std::sin(log.samples[k].pivot_rad[castor]);
    c += std::cos(log.samples[k].pivot_rad[castor]);
  }
  return std::atan2(s, c);
}

// Total rotation of castor j's pivot encoder, unwrapped sample to sample.
double PivotRotation(const EncoderLog& log, int castor) {
  double total = 0.0;
  for (std::size_t k = 1; k < log.samples.size(); ++k) {
    total += WrapAngle(log.samples[k].pivot_rad[castor] - log.samples[k - 1].pivot_rad[castor]);
  }
  return total;
}

}  // namespace

bool GeometricOptions::IsValid(std::string* error) const {
  if (!(steady_fraction > 0.0 && steady_fraction <= 1.0)) {
    *error = "steady_fraction must be in (0, 1]";
    return false;
  }
  return true;
}

CastorParameters SolveHoldPair(const HoldMeasurement& m, double pivot_distance_m,
                               double theta_perp_rad) {
  const double dccw = m.rotation_ccw_rad, dcw = m.rotation_cw_rad;
  // Eq. 1, with the difference taken on the circle.
  const double diff = WrapAngle(m.gamma_ccw_rad - m.gamma_cw_rad);
  const double gamma_path = 0.5 * (M_PI - diff);
  CastorParameters out;
  // Eq. 2: (gamma_ccw + gamma_cw) / 2 as gamma_cw + diff / 2 keeps it on the right turn.
  out.encoder_bias_rad = WrapAngle(m.gamma_cw_rad + 0.5 * diff - 0.5 * M_PI - theta_perp_rad);
  out.offset_m = pivot_distance_m * std::sin(gamma_path);  // Eq. 3
  const double d_cos = pivot_distance_m * std::cos(gamma_path);
  for (int k = 0; k < 2; ++k) {
    const double den = dccw * m.wheel_cw_rad[k] + dcw * m.wheel_ccw_rad[k];
    const double sign = k == 0 ? 1.0 : -1.0;
    out.wheel_radius_m[k] = 2.0 * d_cos * dccw * dcw / den;  // Eq. 8
    out.wheel_offset_m[k] =
        sign * d_cos * (dccw * m.wheel_cw_rad[k] - dcw * m.wheel_ccw_rad[k]) / den;  // Eq. 9
  }
  return out;
}

GeometricResult CalibrateGeometric(const std::vector<RunLog>& runs, const Vehicle& nominal,
                                   const GeometricOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("GeometricOptions: " + error);
  // hold runs by (held castor, direction).
  std::map<std::pair<int, int>, const RunLog*> hold;
  for (const RunLog& run : runs) {
    for (int j = 0; j < kNumCastors; ++j) {
      const std::string prefix = "hold_" + std::to_string(j + 1);
      if (run.trajectory == prefix + "_cw") hold[{j, -1}] = &run;
      if (run.trajectory == prefix + "_ccw") hold[{j, +1}] = &run;
    }
  }
  GeometricResult result;
  result.estimate = nominal;
  std::array<std::vector<CastorParameters>, kNumCastors> estimates;
  for (int j = 0; j < kNumCastors; ++j) {
    const auto cw = hold.find({j, -1}), ccw = hold.find({j, +1});
    if (cw == hold.end() || ccw == hold.end()) continue;
    const EncoderLog& log_cw = cw->second->encoders;
    const EncoderLog& log_ccw = ccw->second->encoders;
    if (log_cw.samples.size() < 4 || log_ccw.samples.size() < 4) continue;
    const double rotation_cw = PivotRotation(log_cw, j);
    const double rotation_ccw = PivotRotation(log_ccw, j);
    // The body turns CW (negative) in a CW run, so the held castor's body-relative angle rises.
    if (!(rotation_cw > 0.0) || !(rotation_ccw < 0.0)) continue;
    for (int i = 0; i < kNumCastors; ++i) {
      if (i == j) continue;
      HoldMeasurement m;
      m.gamma_cw_rad = SteadyAngle(log_cw, i, options.steady_fraction);
      m.gamma_ccw_rad = SteadyAngle(log_ccw, i, options.steady_fraction);
      for (int k = 0; k < 2; ++k) {
        m.wheel_cw_rad[k] =
            log_cw.samples.back().wheel_rad[i][k] - log_cw.samples.front().wheel_rad[i][k];
        m.wheel_ccw_rad[k] =
            log_ccw.samples.back().wheel_rad[i][k] - log_ccw.samples.front().wheel_rad[i][k];
      }
      m.rotation_cw_rad = rotation_cw;
      m.rotation_ccw_rad = -rotation_ccw;
      const double ex = nominal.pivots[i].x_m() - nominal.pivots[j].x_m();
      const double ey = nominal.pivots[i].y_m() - nominal.pivots[j].y_m();
      const double theta_perp = std::atan2(ey, ex) - 0.5 * M_PI;
      estimates[i].push_back(SolveHoldPair(m, nominal.PivotDistance(i, j), theta_perp));
    }
  }
  result.usable = true;
  for (int i = 0; i < kNumCastors; ++i) {
    const auto& e = estimates[i];
    result.num_estimates[i] = static_cast<int>(e.size());
    if (e.empty()) {
      result.usable = false;
      result.message += "castor " + std::to_string(i + 1) + " has no CW+CCW pair of hold runs; ";
      continue;
    }
    double p[kParametersPerCastor] = {0, 0, 0, 0, 0, 0};
    double bs = 0.0, bc = 0.0;
    for (const CastorParameters& c : e) {
      double q[kParametersPerCastor];
      c.ToArray(q);
      for (int k = 0; k < kParametersPerCastor; ++k) p[k] += q[k] / e.size();
      bs += std::sin(c.encoder_bias_rad);
      bc += std::cos(c.encoder_bias_rad);
    }
    p[kBiasIndex] = std::atan2(bs, bc);
    result.estimate.castors[i] = CastorParameters::FromArray(p);
    if (e.size() == 2) {
      double a[kParametersPerCastor], b[kParametersPerCastor], h[kParametersPerCastor];
      e[0].ToArray(a);
      e[1].ToArray(b);
      for (int k = 0; k < kParametersPerCastor; ++k) h[k] = 0.5 * std::abs(a[k] - b[k]);
      h[kBiasIndex] = 0.5 * std::abs(WrapAngle(a[kBiasIndex] - b[kBiasIndex]));
      result.half_spread[i] = CastorParameters::FromArray(h);
    }
    double check[kParametersPerCastor];
    result.estimate.castors[i].ToArray(check);
    for (int k = 0; k < kParametersPerCastor; ++k) {
      if (!std::isfinite(check[k]) || (k != kBiasIndex && !(check[k] > 0.0))) {
        result.usable = false;
        result.message += "castor " + std::to_string(i + 1) + " gives a non-physical estimate; ";
        break;
      }
    }
  }
  if (result.usable)
    result.message = "closed form (Eq. 1-9) from " + std::to_string(hold.size()) + " hold runs";
  return result;
}

}  // namespace fitcal::asoc
