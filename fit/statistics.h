#pragma once
// Tail probabilities for the tests of the effect tracing (diagnosis/diagnose.h), the verdicts
// (validation/) and the noise levels' session test (fit/noise_levels.h): Student t and
// Fisher F, through the regularised incomplete beta function I_x(a, b) (continued fraction of
// Numerical Recipes 3rd ed. Sec. 6.4, Lentz's method); chi-square through the regularised
// incomplete gamma function Q(a, x) (series and continued fraction, Sec. 6.2).

#include <vector>

namespace fitcal::stats {

// I_x(a, b), a, b > 0, x in [0, 1].
double RegularizedIncompleteBeta(double a, double b, double x);
// P(T > t) for Student's t with df degrees of freedom.
double StudentTUpperTail(double t, double df);
// The t with P(T > t) = upper_tail (0 < upper_tail < 0.5), by bisection on StudentTUpperTail.
double StudentTUpperQuantile(double upper_tail, double df);
// P(F > f) for Fisher's F(d1, d2).
double FUpperTail(double f, double d1, double d2);
// Q(a, x) = Gamma(a, x) / Gamma(a), a > 0, x >= 0.
double RegularizedUpperGamma(double a, double x);
// P(X > chi2) for X chi-square with df degrees of freedom.
double ChiSquareUpperTail(double chi2, double df);
// The middle value of `v` (not empty), the mean of the two middle ones for an even count.
double Median(std::vector<double> v);

// The one-sided paired t test that `candidate`'s per-run errors are lower than `base`'s, on the
// log ratios l_i = ln(base_i / candidate_i): an effect scales each run's error by that run's
// exposure to it, so the differences are heavy-tailed while the ratios are comparable across
// runs. p = P(T > t) on n - 1 df (1 for fewer than two runs).
struct PairedTest {
  double t = 0.0;
  double p = 1.0;
};
PairedTest PairedLogRatioTest(const std::vector<double>& base,
                              const std::vector<double>& candidate);

}  // namespace fitcal::stats
