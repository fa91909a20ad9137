#include "odometry/reading_resolution.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

namespace fitcal {

double ReadingResolution::NoiseOverStep() const {
  return readings == 0 ? 0.0
                       : NoiseOverStepOfReversals(static_cast<double>(reversals) /
                                                  static_cast<double>(readings));
}

double ReadingResolution::BiasSigma() const {
  const double s = NoiseOverStep();
  return step_rad / std::sqrt(12.0) * std::exp(-2.0 * M_PI * M_PI * s * s);
}

namespace {

// The flicker rate of a held angle over noise sigma_n = s q (NoiseOverStepOfReversals): the mean
// of p (1 - p) over the count [-1/2, 1/2], by the midpoint rule on 400 points.
double ReversalsOfNoiseOverStep(double s) {
  if (s <= 0.0) return 0.0;
  const auto normal_cdf = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  constexpr int kPoints = 400;
  double sum = 0.0;
  for (int i = 0; i < kPoints; ++i) {
    const double u = -0.5 + (i + 0.5) / kPoints;
    const double p = normal_cdf((u - 0.5) / s) + normal_cdf((-0.5 - u) / s);
    sum += p * (1.0 - p);
  }
  return sum / kPoints;
}

}  // namespace

double NoiseOverStepOfReversals(double reversals_per_reading) {
  constexpr double kMax = 0.5;
  if (!(reversals_per_reading > 0.0)) return 0.0;
  if (reversals_per_reading >= ReversalsOfNoiseOverStep(kMax)) return kMax;
  double lo = 0.0, hi = kMax;  // the rate rises with s on [0, 0.5]
  for (int i = 0; i < 50; ++i) {
    const double mid = 0.5 * (lo + hi);
    (ReversalsOfNoiseOverStep(mid) < reversals_per_reading ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

void ReadingGrid::Add(double reading) {
  if (!std::isfinite(reading)) return;
  if (total_ >= 2) {
    ++with_two_before_;
    if (last_ != before_ && reading == before_) ++reversals_;
  }
  before_ = last_;
  last_ = reading;
  ++total_;
  if (continuous_) return;
  ++count_of_value_[reading];
  if (count_of_value_.size() > static_cast<std::size_t>(kMaxDistinct)) {
    continuous_ = true;
    count_of_value_.clear();
  }
}

ReadingResolution ReadingGrid::Resolution(double known_step_rad) const {
  const double step = known_step_rad > 0.0 ? known_step_rad : Step();
  return step > 0.0 ? ReadingResolution{step, with_two_before_, reversals_} : ReadingResolution{};
}

double ReadingGrid::Step() const {
  if (continuous_ || count_of_value_.size() < static_cast<std::size_t>(kMinGridValues)) {
    return 0.0;
  }
  std::vector<double> gaps;
  double previous = count_of_value_.begin()->first;
  for (auto it = std::next(count_of_value_.begin()); it != count_of_value_.end(); ++it) {
    gaps.push_back(it->first - previous);
    previous = it->first;
  }
  // A fast sweep skips counts, so most gaps may be several steps; a glitch makes a few odd small
  // ones. The 10th percentile is a step.
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 10),
                   gaps.end());
  const double step = gaps[gaps.size() / 10];
  const auto mode = std::max_element(
      count_of_value_.begin(), count_of_value_.end(),
      [](const auto& a, const auto& b) { return a.second < b.second; });
  std::int64_t on_grid = 0;
  int grid_values = 0;
  for (const auto& [value, count] : count_of_value_) {
    const double k = (value - mode->first) / step;
    if (std::abs(k - std::round(k)) > 0.01) continue;
    on_grid += count;
    ++grid_values;
  }
  const bool on_a_grid = static_cast<double>(on_grid) >= 0.99 * static_cast<double>(total_);
  return on_a_grid && grid_values >= kMinGridValues && step >= kMinStepRad ? step : 0.0;
}

}  // namespace fitcal
