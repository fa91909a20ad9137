#include "models/asoc/asoc_geometric.h"

#include <algorithm>
#include <cmath>
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

bool ParseHoldLabel(const std::string& trajectory, int* held, int* direction) {
  for (int j = 0; j < kNumCastors; ++j) {
    const std::string prefix = "hold_" + std::to_string(j + 1);
    if (trajectory == prefix + "_cw" || trajectory == prefix + "_ccw") {
      *held = j;
      *direction = trajectory == prefix + "_cw" ? -1 : +1;
      return true;
    }
  }
  return false;
}

HoldRun MeasureHoldRun(const EncoderLog& log, int held, int direction, double steady_fraction) {
  HoldRun run;
  run.held = held;
  run.direction = direction;
  run.rotation_rad = PivotRotation(log, held);
  for (int i = 0; i < kNumCastors; ++i) {
    run.steady_gamma_rad[i] = SteadyAngle(log, i, steady_fraction);
    for (int k = 0; k < 2; ++k) {
      run.wheel_rad[i][k] =
          log.samples.back().wheel_rad[i][k] - log.samples.front().wheel_rad[i][k];
    }
  }
  return run;
}

namespace {

// The estimates of castor i from every CW x CCW pair of runs holding castor j != i; sets
// used[r] for the runs that entered a pair.
std::array<std::vector<CastorParameters>, kNumCastors> PairEstimates(
    const std::vector<HoldRun>& runs, const Vehicle& nominal, std::vector<bool>* used) {
  std::array<std::vector<CastorParameters>, kNumCastors> estimates;
  for (int j = 0; j < kNumCastors; ++j) {
    for (std::size_t a = 0; a < runs.size(); ++a) {
      // The body turns CW (negative) in a CW run, so the held castor's body-relative angle rises.
      const HoldRun& cw = runs[a];
      if (cw.held != j || cw.direction != -1 || !(cw.rotation_rad > 0.0)) continue;
      for (std::size_t b = 0; b < runs.size(); ++b) {
        const HoldRun& ccw = runs[b];
        if (ccw.held != j || ccw.direction != +1 || !(ccw.rotation_rad < 0.0)) continue;
        (*used)[a] = (*used)[b] = true;
        for (int i = 0; i < kNumCastors; ++i) {
          if (i == j) continue;
          HoldMeasurement m;
          m.gamma_cw_rad = cw.steady_gamma_rad[i];
          m.gamma_ccw_rad = ccw.steady_gamma_rad[i];
          m.wheel_cw_rad = cw.wheel_rad[i];
          m.wheel_ccw_rad = ccw.wheel_rad[i];
          m.rotation_cw_rad = cw.rotation_rad;
          m.rotation_ccw_rad = -ccw.rotation_rad;
          const double ex = nominal.pivots[i].x_m() - nominal.pivots[j].x_m();
          const double ey = nominal.pivots[i].y_m() - nominal.pivots[j].y_m();
          const double theta_perp = std::atan2(ey, ex) - 0.5 * M_PI;
          estimates[i].push_back(SolveHoldPair(m, nominal.PivotDistance(i, j), theta_perp));
        }
      }
    }
  }
  return estimates;
}

// The mean of a castor's estimates (beta on the circle) and their half range per parameter.
void AverageEstimates(const std::vector<CastorParameters>& e, CastorParameters* mean,
                      CastorParameters* half_spread) {
  double p[kParametersPerCastor] = {0, 0, 0, 0, 0, 0};
  double lo[kParametersPerCastor] = {0, 0, 0, 0, 0, 0},
         hi[kParametersPerCastor] = {0, 0, 0, 0, 0, 0};
  double bs = 0.0, bc = 0.0;
  for (std::size_t n = 0; n < e.size(); ++n) {
    double q[kParametersPerCastor];
    e[n].ToArray(q);
    for (int k = 0; k < kParametersPerCastor; ++k) {
      p[k] += q[k] / e.size();
      lo[k] = n == 0 ? q[k] : std::min(lo[k], q[k]);
      hi[k] = n == 0 ? q[k] : std::max(hi[k], q[k]);
    }
    bs += std::sin(e[n].encoder_bias_rad);
    bc += std::cos(e[n].encoder_bias_rad);
  }
  p[kBiasIndex] = std::atan2(bs, bc);
  *mean = CastorParameters::FromArray(p);
  double h[kParametersPerCastor];
  for (int k = 0; k < kParametersPerCastor; ++k) h[k] = 0.5 * (hi[k] - lo[k]);
  double bias_spread = 0.0;  // on the circle, from the mean
  for (const CastorParameters& c : e) {
    bias_spread = std::max(bias_spread, std::abs(WrapAngle(c.encoder_bias_rad - p[kBiasIndex])));
  }
  h[kBiasIndex] = bias_spread;
  *half_spread = CastorParameters::FromArray(h);
}

}  // namespace

GeometricResult CalibrateFromHoldRuns(const std::vector<HoldRun>& runs, const Vehicle& nominal) {
  GeometricResult result;
  result.estimate = nominal;
  std::vector<bool> used(runs.size(), false);
  const auto estimates = PairEstimates(runs, nominal, &used);
  result.usable = true;
  for (int i = 0; i < kNumCastors; ++i) {
    const auto& e = estimates[i];
    result.num_estimates[i] = static_cast<int>(e.size());
    if (e.empty()) {
      result.usable = false;
      result.message += "castor " + std::to_string(i + 1) + " has no CW+CCW pair of hold runs; ";
      continue;
    }
    AverageEstimates(e, &result.estimate.castors[i], &result.half_spread[i]);
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
  if (result.usable) {
    const auto n = std::count(used.begin(), used.end(), true);
    result.message = "closed form (Eq. 1-9) from " + std::to_string(n) + " of " +
                     std::to_string(runs.size()) + " hold runs";
  }
  return result;
}

GeometricResult CalibrateGeometric(const std::vector<RunLog>& runs, const Vehicle& nominal,
                                   const GeometricOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("GeometricOptions: " + error);
  std::vector<HoldRun> holds;
  for (const RunLog& run : runs) {
    int held = 0, direction = 0;
    if (!ParseHoldLabel(run.trajectory, &held, &direction)) continue;
    if (run.encoders.samples.size() < 4) continue;
    holds.push_back(MeasureHoldRun(run.encoders, held, direction, options.steady_fraction));
  }
  return CalibrateFromHoldRuns(holds, nominal);
}

}  // namespace fitcal::asoc
