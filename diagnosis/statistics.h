#pragma once
// Tail probabilities for the tests of the effect tracing (diagnosis/diagnose.h): Student t and
// Fisher F, through the regularised incomplete beta function I_x(a, b) (continued fraction of
// Numerical Recipes 3rd ed. Sec. 6.4, Lentz's method).

namespace fitcal::stats {

// I_x(a, b), a, b > 0, x in [0, 1].
double RegularizedIncompleteBeta(double a, double b, double x);
// P(T > t) for Student's t with df degrees of freedom.
double StudentTUpperTail(double t, double df);
// P(F > f) for Fisher's F(d1, d2).
double FUpperTail(double f, double d1, double d2);

}  // namespace fitcal::stats
