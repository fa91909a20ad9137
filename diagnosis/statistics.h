#pragma once
// Tail probabilities for the tests of the effect tracing (diagnosis/diagnose.h): Student t and
// Fisher F, through the regularised incomplete beta function I_x(a, b) (continued fraction of
// Numerical Recipes 3rd ed. Sec. 6.4, Lentz's method); chi-square through the regularised
// incomplete gamma function Q(a, x) (series and continued fraction, Sec. 6.2).

namespace fitcal::stats {

// I_x(a, b), a, b > 0, x in [0, 1].
double RegularizedIncompleteBeta(double a, double b, double x);
// P(T > t) for Student's t with df degrees of freedom.
double StudentTUpperTail(double t, double df);
// P(F > f) for Fisher's F(d1, d2).
double FUpperTail(double f, double d1, double d2);
// Q(a, x) = Gamma(a, x) / Gamma(a), a > 0, x >= 0.
double RegularizedUpperGamma(double a, double x);
// P(X > chi2) for X chi-square with df degrees of freedom.
double ChiSquareUpperTail(double chi2, double df);

}  // namespace fitcal::stats
