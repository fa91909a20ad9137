#include "fit/statistics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fitcal::stats {

namespace {

double BetaContinuedFraction(double a, double b, double x) {
  constexpr int kMaxIterations = 300;
  constexpr double kEpsilon = 1e-15;
  constexpr double kTiny = 1e-300;
  const double qab = a + b, qap = a + 1.0, qam = a - 1.0;
  double c = 1.0;
  double d = 1.0 - qab * x / qap;
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= kMaxIterations; ++m) {
    const int m2 = 2 * m;
    double aa = m * (b - m) * x / ((qam + m2) * (a + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    h *= d * c;
    aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
    d = 1.0 + aa * d;
    if (std::abs(d) < kTiny) d = kTiny;
    c = 1.0 + aa / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < kEpsilon) break;
  }
  return h;
}

}  // namespace

double RegularizedIncompleteBeta(double a, double b, double x) {
  if (!(a > 0.0 && b > 0.0) || !(x >= 0.0 && x <= 1.0))
    return std::numeric_limits<double>::quiet_NaN();
  if (x == 0.0 || x == 1.0) return x;
  const double log_front =
      std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
  const double front = std::exp(log_front);
  if (x < (a + 1.0) / (a + b + 2.0)) return front * BetaContinuedFraction(a, b, x) / a;
  return 1.0 - front * BetaContinuedFraction(b, a, 1.0 - x) / b;
}

double StudentTUpperTail(double t, double df) {
  const double x = df / (df + t * t);
  const double two_sided = RegularizedIncompleteBeta(0.5 * df, 0.5, x);
  return t >= 0.0 ? 0.5 * two_sided : 1.0 - 0.5 * two_sided;
}

double StudentTUpperQuantile(double upper_tail, double df) {
  // P(T > t) falls monotonically in t; 1e6 bounds every quantile used (df >= 1, tail >= 1e-6).
  double lo = 0.0, hi = 1e6;
  for (int i = 0; i < 200 && hi - lo > 1e-10 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (StudentTUpperTail(mid, df) > upper_tail ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double FUpperTail(double f, double d1, double d2) {
  if (!(f > 0.0)) return 1.0;
  return RegularizedIncompleteBeta(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f));
}

namespace {

// P(a, x) by its series, for x < a + 1 (Numerical Recipes 3rd ed. Sec. 6.2).
double LowerGammaSeries(double a, double x) {
  constexpr int kMaxIterations = 100000;
  double ap = a, del = 1.0 / a, sum = del;
  for (int n = 0; n < kMaxIterations; ++n) {
    ap += 1.0;
    del *= x / ap;
    sum += del;
    if (std::abs(del) < std::abs(sum) * 1e-15) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) by its continued fraction (modified Lentz), for x >= a + 1.
double UpperGammaContinuedFraction(double a, double x) {
  constexpr int kMaxIterations = 100000;
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < kMaxIterations; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

}  // namespace

double RegularizedUpperGamma(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) return std::numeric_limits<double>::quiet_NaN();
  if (x == 0.0) return 1.0;
  if (x < a + 1.0) return 1.0 - LowerGammaSeries(a, x);
  return UpperGammaContinuedFraction(a, x);
}

double ChiSquareUpperTail(double chi2, double df) {
  return RegularizedUpperGamma(0.5 * df, 0.5 * std::max(chi2, 0.0));
}

double Median(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  if (v.size() % 2 == 1) return v[mid];
  const double upper = v[mid];
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
}

PairedTest PairedLogRatioTest(const std::vector<double>& base,
                              const std::vector<double>& candidate) {
  const std::size_t n = std::min(base.size(), candidate.size());
  constexpr double kTiny = 1e-300;
  std::vector<double> l(n);
  double mean = 0.0, var = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    l[i] = std::log(std::max(base[i], kTiny) / std::max(candidate[i], kTiny));
    mean += l[i];
  }
  PairedTest out;
  if (n < 2) return out;
  const double count = static_cast<double>(n);
  mean /= count;
  for (double x : l) var += (x - mean) * (x - mean);
  var /= count - 1.0;
  out.t = var > 0.0 ? mean / std::sqrt(var / count) : 0.0;
  out.p = StudentTUpperTail(out.t, count - 1.0);
  return out;
}

}  // namespace fitcal::stats
