#pragma once
// sin and cos of one angle, on double or ceres::Jet, computed once. Why: ceres' sin(Jet) and
// cos(Jet) each evaluate both sin(a) and cos(a) of the real part (the value and the derivative),
// and GCC does not merge the two libm calls across them, so a step that needs both paid two
// sincos calls where one suffices (perf of `fitcal diagnose` on a differential drive: 12 % of it
// in sincos). The results are bit for bit ceres' own: the same products in the same order.

#include <cmath>
#include <cstdint>
#include <cstring>

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

// sin and cos of an angle that often repeats from one call to the next, as SinCos. Why: a
// tricycle's steering angle is its encoder reading, which holds for most samples (72-98 % of the
// OptiOdom tricycle's), and its replay on Jets spent 22 % in libm's sincos (perf of a
// RecordedRobot tricycle fit). The last angle and its pair are kept per thread (no state shared
// between threads), the angle compared bit for bit (so +0 and -0, whose sines differ, never
// share a pair): every result is libm's for that angle, the same bits as SinCos.
inline void SinCosOfRepeatedAngle(double angle_rad, double* sin_out, double* cos_out) {
  struct Last {
    bool valid = false;
    std::uint64_t angle_bits = 0;
    double sin = 0.0;
    double cos = 0.0;
  };
  thread_local Last last;
  std::uint64_t bits;
  std::memcpy(&bits, &angle_rad, sizeof bits);
  if (!last.valid || bits != last.angle_bits) {
    last = {true, bits, std::sin(angle_rad), std::cos(angle_rad)};
  }
  *sin_out = last.sin;
  *cos_out = last.cos;
}

// The same for ceres::Jet: the real part's pair through the cache, the derivatives as SinCos's.
template <typename JetT>
void SinCosOfRepeatedAngle(const JetT& f, JetT* sin_out, JetT* cos_out) {
  double s, c;
  SinCosOfRepeatedAngle(f.a, &s, &c);
  *sin_out = JetT(s, c * f.v);
  *cos_out = JetT(c, -s * f.v);
}

}  // namespace fitcal
