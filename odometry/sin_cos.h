#pragma once
// sin and cos of one angle, on double or ceres::Jet, computed once. Why: ceres' sin(Jet) and
// cos(Jet) each evaluate both sin(a) and cos(a) of the real part (the value and the derivative),
// and GCC does not merge the two libm calls across them, so a step that needs both paid two
// sincos calls where one suffices (perf of `fitcal diagnose` on a differential drive: 12 % of it
// in sincos). The results are bit for bit ceres' own: the same products in the same order.

#include <cmath>

namespace fitcal {

inline void SinCos(double angle_rad, double* sin_out, double* cos_out) {
  *sin_out = std::sin(angle_rad);
  *cos_out = std::cos(angle_rad);
}

// For ceres::Jet (found by overload, as ScalarPart in pose2.h, so odometry/ needs no Ceres
// header): sin(f) = (sin a, cos a * v), cos(f) = (cos a, -sin a * v), as ceres/jet.h writes them.
template <typename JetT>
void SinCos(const JetT& f, JetT* sin_out, JetT* cos_out) {
  const double s = std::sin(f.a);
  const double c = std::cos(f.a);
  *sin_out = JetT(s, c * f.v);
  *cos_out = JetT(c, -s * f.v);
}

}  // namespace fitcal
