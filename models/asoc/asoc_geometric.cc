#include "models/asoc/asoc_geometric.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "odometry/pose2.h"

namespace fitcal::asoc {

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

namespace {

// "hold_<j>_cw" / "hold_<j>_ccw" (j = 1..3): the held castor (0-based) and the direction.
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

}  // namespace

std::optional<HoldRun> MeasureHoldRun(const std::string& trajectory,
                                      const EncoderSamples& samples) {
  HoldRun run;
  const std::size_t n = samples.size();
  if (!ParseHoldLabel(trajectory, &run.held, &run.direction) || n < 4) return std::nullopt;
  const std::size_t skip = static_cast<std::size_t>(std::floor(0.5 * (1.0 - kSteadyFraction) * n));
  const int held_pivot = run.held * kChannelsPerCastor + kPivotChannel;
  for (std::size_t k = 1; k < n; ++k) {
    run.rotation_rad += WrapAngle(samples[k].value[held_pivot] - samples[k - 1].value[held_pivot]);
  }
  for (int i = 0; i < kNumCastors; ++i) {
    const int base = i * kChannelsPerCastor;
    double s = 0.0, c = 0.0;
    for (std::size_t k = skip; k < n - skip; ++k) {
      s += std::sin(samples[k].value[base + kPivotChannel]);
      c += std::cos(samples[k].value[base + kPivotChannel]);
    }
    run.steady_gamma_rad[i] = std::atan2(s, c);
    for (int w = 0; w < 2; ++w) {
      const int ch = base + (w == 0 ? kWheelAChannel : kWheelBChannel);
      double angle = 0.0;
      for (const auto& sample : samples) angle += sample.value[ch] * sample.dt_s;
      // From the middle of the first interval to the middle of the last, as the pivot's turn.
      angle -= 0.5 * (samples[0].value[ch] * samples[0].dt_s +
                      samples[n - 1].value[ch] * samples[n - 1].dt_s);
      run.wheel_rad[i][w] = angle;
    }
  }
  return run;
}

namespace {

// Per active castor i and held castor j, the estimates of castor i from every CW x CCW pair of
// runs holding j; sets used[r] for the runs that entered a pair.
// With `pivot_resolution_rad` > 0, each pair's variance from the pivot encoders' quantisation
// (QuantisationVariance) goes with it.
struct PairEstimate {
  CastorParameters value;
  std::array<double, kParametersPerCastor> quantisation_variance{};
};
using PairEstimateTable =
    std::array<std::array<std::vector<PairEstimate>, kNumCastors>, kNumCastors>;

// The variance Eq. 1-9's estimates get from the pivot encoders' step q, propagated through
// SolveHoldPair by central differences: a steady reading gamma is off by a uniform +-q/2 (var
// q^2/12: a constant quantised reading is not averaged down), a rotation dtheta, the difference
// of two readings, by var q^2/6. The wheel encoders' step is left out: over a hold run's
// rotation it is a relative 1e-4 of the wheel angle.
std::array<double, kParametersPerCastor> QuantisationVariance(const HoldMeasurement& m, double d_m,
                                                              double theta_perp_rad, double q) {
  std::array<double, kParametersPerCastor> var{};
  if (!(q > 0.0)) return var;
  double* inputs[4];
  HoldMeasurement x = m;
  inputs[0] = &x.gamma_cw_rad;
  inputs[1] = &x.gamma_ccw_rad;
  inputs[2] = &x.rotation_cw_rad;
  inputs[3] = &x.rotation_ccw_rad;
  const double input_var[4] = {q * q / 12.0, q * q / 12.0, q * q / 6.0, q * q / 6.0};
  constexpr double kStep = 1e-6;  // rad: the outputs are smooth over many q
  for (int a = 0; a < 4; ++a) {
    const double saved = *inputs[a];
    double hi[kParametersPerCastor], lo[kParametersPerCastor];
    *inputs[a] = saved + kStep;
    SolveHoldPair(x, d_m, theta_perp_rad).ToArray(hi);
    *inputs[a] = saved - kStep;
    SolveHoldPair(x, d_m, theta_perp_rad).ToArray(lo);
    *inputs[a] = saved;
    for (int k = 0; k < kParametersPerCastor; ++k) {
      const double derivative =
          (k == kBiasIndex ? WrapAngle(hi[k] - lo[k]) : hi[k] - lo[k]) / (2.0 * kStep);
      var[k] += derivative * derivative * input_var[a];
    }
  }
  return var;
}

PairEstimateTable PairEstimates(const std::vector<HoldRun>& runs, const Vehicle& nominal,
                                double pivot_resolution_rad, std::vector<bool>* used) {
  PairEstimateTable estimates;
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
          const double d = nominal.PivotDistance(i, j);
          estimates[i][j].push_back({SolveHoldPair(m, d, theta_perp),
                                     QuantisationVariance(m, d, theta_perp, pivot_resolution_rad)});
        }
      }
    }
  }
  return estimates;
}

// The mean of estimates (beta on the circle).
CastorParameters MeanOf(const std::vector<CastorParameters>& e) {
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
  return CastorParameters::FromArray(p);
}

// q - mean per parameter, beta's on the circle.
void DeviationFrom(const CastorParameters& q, const CastorParameters& mean, double* d) {
  double a[kParametersPerCastor], b[kParametersPerCastor];
  q.ToArray(a);
  mean.ToArray(b);
  for (int k = 0; k < kParametersPerCastor; ++k) d[k] = a[k] - b[k];
  d[kBiasIndex] = WrapAngle(d[kBiasIndex]);
}

// t with P(|T| < t) = 68.27 % (the normal's 1 sigma) for Student's t with dof degrees of freedom:
// a standard error from dof degrees of freedom times t covers the error as often as one normal
// sigma does. dof 1..10 from a table (computed by integrating the density); beyond,
// 1 + 1/(2 dof) to 0.3 %; infinity for dof < 1.
double OneSigmaStudentFactor(int dof) {
  static constexpr double kTable[] = {1.8373, 1.3213, 1.1969, 1.1416, 1.1105,
                                      1.0906, 1.0767, 1.0665, 1.0587, 1.0526};
  if (dof < 1) return std::numeric_limits<double>::infinity();
  if (dof <= 10) return kTable[dof - 1];
  return 1.0 + 0.5 / dof;
}

// The sigmas of the castor estimates from the spread of their independent estimates (one per
// held castor: different runs); the pair estimates of one held castor share runs, so they are
// averaged first. Each parameter slot's variance is pooled over the castors (same geometry, same
// encoders): s_k^2 = sum_i sum_j (g_ijk - mean_ik)^2 / dof, dof = sum_i (G_i - 1); castor i's
// mean of G_i estimates has sigma t(dof) s_k / sqrt(G_i), t widening the 1-sigma interval for the
// few degrees of freedom (3 with one CW and one CCW run per castor).
void SpreadSigmas(
    const std::array<std::vector<CastorParameters>, kNumCastors>& group_means,
    const std::array<std::array<double, kParametersPerCastor>, kNumCastors>& quantisation_variance,
    GeometricResult* result) {
  double ss[kParametersPerCastor] = {0, 0, 0, 0, 0, 0};
  int dof = 0;
  for (int i = 0; i < kNumCastors; ++i) {
    const auto& g = group_means[i];
    if (g.empty()) continue;
    dof += static_cast<int>(g.size()) - 1;
    for (const CastorParameters& q : g) {
      double d[kParametersPerCastor];
      DeviationFrom(q, result->estimate.castors[i], d);
      for (int k = 0; k < kParametersPerCastor; ++k) ss[k] += d[k] * d[k];
    }
  }
  result->sigma_dof = dof;
  if (dof < 1) return;
  const double t = OneSigmaStudentFactor(dof);
  for (int i = 0; i < kNumCastors; ++i) {
    if (group_means[i].empty()) continue;
    double s[kParametersPerCastor];
    for (int k = 0; k < kParametersPerCastor; ++k) {
      const double spread = t * std::sqrt(ss[k] / dof / static_cast<double>(group_means[i].size()));
      s[k] = std::sqrt(spread * spread + quantisation_variance[i][k]);
    }
    result->sigma[i] = CastorParameters::FromArray(s);
  }
}

// Castor i's estimate is the mean of its held castors' means; false when any parameter is not
// finite or not positive (beta aside).
bool Physical(const CastorParameters& c) {
  double check[kParametersPerCastor];
  c.ToArray(check);
  for (int k = 0; k < kParametersPerCastor; ++k) {
    if (!std::isfinite(check[k]) || (k != kBiasIndex && !(check[k] > 0.0))) return false;
  }
  return true;
}

}  // namespace

GeometricResult CalibrateFromHoldRuns(const std::vector<HoldRun>& runs, const Vehicle& nominal,
                                      double pivot_resolution_rad) {
  GeometricResult result;
  result.estimate = nominal;
  std::vector<bool> used(runs.size(), false);
  const PairEstimateTable estimates = PairEstimates(runs, nominal, pivot_resolution_rad, &used);
  std::array<std::vector<CastorParameters>, kNumCastors> group_means;
  // Per castor: the quantisation variance of its mean of group means (a group's pairs share runs,
  // so its variance is taken as its pairs' mean, not divided by their number).
  std::array<std::array<double, kParametersPerCastor>, kNumCastors> quantisation{};
  result.usable = true;
  for (int i = 0; i < kNumCastors; ++i) {
    std::vector<CastorParameters> all;
    int groups = 0;
    for (int j = 0; j < kNumCastors; ++j) groups += estimates[i][j].empty() ? 0 : 1;
    for (int j = 0; j < kNumCastors; ++j) {
      if (estimates[i][j].empty()) continue;
      std::vector<CastorParameters> values;
      for (const PairEstimate& e : estimates[i][j]) {
        values.push_back(e.value);
        for (int k = 0; k < kParametersPerCastor; ++k) {
          quantisation[i][k] += e.quantisation_variance[k] /
                                (static_cast<double>(estimates[i][j].size()) * groups * groups);
        }
      }
      group_means[i].push_back(MeanOf(values));
      all.insert(all.end(), values.begin(), values.end());
    }
    result.num_estimates[i] = static_cast<int>(all.size());
    if (all.empty()) {
      result.usable = false;
      result.message += "castor " + std::to_string(i + 1) + " has no CW+CCW pair of hold runs; ";
      continue;
    }
    result.estimate.castors[i] = MeanOf(group_means[i]);
    if (!Physical(result.estimate.castors[i])) {
      result.usable = false;
      result.message += "castor " + std::to_string(i + 1) + " gives a non-physical estimate; ";
    }
  }
  SpreadSigmas(group_means, quantisation, &result);
  if (result.usable) {
    const auto n = std::count(used.begin(), used.end(), true);
    result.message = "closed form (Eq. 1-9) from " + std::to_string(n) + " of " +
                     std::to_string(runs.size()) + " hold runs";
  }
  return result;
}

GeometricResult CalibrateGeometric(const std::vector<fitcal::RunLog>& runs, const Vehicle& nominal,
                                   double pivot_resolution_rad) {
  std::vector<HoldRun> holds;
  for (const fitcal::RunLog& run : runs) {
    if (const auto hold = MeasureHoldRun(run.trajectory, run.encoders.samples)) {
      holds.push_back(*hold);
    }
  }
  return CalibrateFromHoldRuns(holds, nominal, pivot_resolution_rad);
}

}  // namespace fitcal::asoc
