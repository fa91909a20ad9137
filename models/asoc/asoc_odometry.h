#pragma once
// The pieces of Doebbler's multi-castor odometry (Sec. III-B) that the seam's body step
// (asoc_kinematics.h) is built from:
//   - CAST-n: the linear least squares of Eq. 13-17 over any subset of >= 2 castors,
//       dx_i = dx_c - dpsi R_i sin(psi + phi_i)   (Eq. 13)
//       dy_i = dy_c + dpsi R_i cos(psi + phi_i)   (Eq. 14)
//     solved with the closed-form (H^T H)^-1 of Eq. 18-21 for pivots anywhere on the body (Eq. 22,
//     for pivots centred on the body origin, is its special case: tests/asoc_odometry_test.cc);
//   - IPEC (Borenstein, Eq. 10) on two castors as the baseline (Method);
// Naming as in Doebbler Table II: CAST-i / IPEC-i leave castor i out (1-based), CAST-0 uses all.
//
// Redundancy check (the paper's future work, Sec. III-B end): with three castors, each castor's
// displacement is predicted from the other two (CAST on the pair). The pair whose own two
// displacements agree best (least change of their pivot distance) names the suspect, the third
// castor; it is dropped for this update when its measured displacement differs from the
// prediction by more than tolerance_m + tolerance_fraction * (the step length).

#include <algorithm>
#include <array>
#include <cmath>

#include "models/asoc/asoc_model.h"

namespace fitcal::asoc {

using CastorMask = unsigned;  // bit i set = castor i (0-based) is used
inline constexpr CastorMask kAllCastors = 0b111;
// CAST-i / IPEC-i of Doebbler Table II: castor i (1-based) left out; i = 0 keeps all.
inline CastorMask MaskExcluding(int castor_one_based) {
  return castor_one_based == 0 ? kAllCastors : (kAllCastors & ~(1u << (castor_one_based - 1)));
}

template <typename T>
struct BodyStep {
  T dx_m;  // dx_c, world frame
  T dy_m;  // dy_c
  T dpsi_rad;
};

// CAST general solution, Eq. 15 with the closed-form inverse of Eq. 18-21:
//   H^T H = [[n, 0, b], [0, n, c], [b, c, d]],
//   b = -n (m_y cos psi + m_x sin psi), c = n (m_x cos psi - m_y sin psi), d = sum R_i^2,
// (Eq. 19 prints m_v for m_y), and H^T Y = [sum dx_i, sum dy_i, sum R_i (c_i dy_i - s_i dx_i)]
// with s_i, c_i = sin, cos(psi + phi_i). (m_x, m_y) is the mean of the used pivots in B.
template <typename T>
BodyStep<T> SolveCastGeneral(const std::array<PivotPosition, kNumCastors>& pivots, CastorMask mask,
                             const T& psi, const T* dx, const T* dy) {
  using std::cos;
  using std::sin;
  const T cp = cos(psi), sp = sin(psi);
  double n = 0.0, mx = 0.0, my = 0.0, d = 0.0;
  T sum_dx(0.0), sum_dy(0.0), sum_rot(0.0);
  for (int i = 0; i < kNumCastors; ++i) {
    if (!((mask >> i) & 1u)) continue;
    const double px = pivots[i].x_m(), py = pivots[i].y_m();
    n += 1.0;
    mx += px;
    my += py;
    d += px * px + py * py;
    const T r_sin = py * cp + px * sp;  // R_i sin(psi + phi_i)
    const T r_cos = px * cp - py * sp;  // R_i cos(psi + phi_i)
    sum_dx += dx[i];
    sum_dy += dy[i];
    sum_rot += r_cos * dy[i] - r_sin * dx[i];
  }
  mx /= n;
  my /= n;
  const T b = -n * (my * cp + mx * sp);  // Eq. 19
  const T c = n * (mx * cp - my * sp);   // Eq. 20
  // Eq. 18: (H^T H)^-1 = 1 / (n (b^2 + c^2 - n d)) [[c^2-nd, -bc, nb], [-bc, b^2-nd, nc],
  //                                                 [nb, nc, -n^2]]
  const T inv = T(1.0) / (n * (b * b + c * c - n * d));
  BodyStep<T> out;
  out.dx_m = inv * ((c * c - n * d) * sum_dx - b * c * sum_dy + n * b * sum_rot);
  out.dy_m = inv * (-b * c * sum_dx + (b * b - n * d) * sum_dy + n * c * sum_rot);
  out.dpsi_rad = inv * (n * b * sum_dx + n * c * sum_dy - n * n * sum_rot);
  return out;
}

// How far a castor's displacement may miss the other two's CAST prediction before the redundancy
// check below names it: an absolute part and a fraction of the step's length.
inline constexpr double kConsistencyToleranceM = 0.5e-3;
inline constexpr double kConsistencyToleranceFraction = 0.1;

// The redundancy check (Doebbler Sec. III-B, end; header above): the castor whose displacement
// (dx_i, dy_i) disagrees with the CAST prediction of the other two by more than
// kConsistencyToleranceM + kConsistencyToleranceFraction * (the step length), or -1. psi: the
// heading the displacements are expressed at (the body frame's, Eq. 13-14).
inline int InconsistentCastor(const std::array<PivotPosition, kNumCastors>& pivots, double psi,
                              const double* dx, const double* dy) {
  int suspect = -1;
  double best_pair_residual = 0.0;
  double step_length = 0.0;
  for (int i = 0; i < kNumCastors; ++i)
    step_length = std::max(step_length, std::hypot(dx[i], dy[i]));
  const double c = std::cos(psi), s = std::sin(psi);
  for (int k = 0; k < kNumCastors; ++k) {
    const int i = (k + 1) % kNumCastors, j = (k + 2) % kNumCastors;
    // Change of the distance between pivots i and j: zero for a rigid body (first order).
    const double ex = pivots[j].x_m() - pivots[i].x_m();
    const double ey = pivots[j].y_m() - pivots[i].y_m();
    const double wx = c * ex - s * ey, wy = s * ex + c * ey;
    const double residual =
        std::abs(((dx[j] - dx[i]) * wx + (dy[j] - dy[i]) * wy) / std::hypot(wx, wy));
    if (suspect < 0 || residual < best_pair_residual) {
      suspect = k;
      best_pair_residual = residual;
    }
  }
  const BodyStep<double> pair =
      SolveCastGeneral(pivots, kAllCastors & ~(1u << suspect), psi, dx, dy);
  const PivotPosition& q = pivots[suspect];
  const double pred_x = pair.dx_m - pair.dpsi_rad * (q.y_m() * c + q.x_m() * s);  // Eq. 13
  const double pred_y = pair.dy_m + pair.dpsi_rad * (q.x_m() * c - q.y_m() * s);  // Eq. 14
  const double miss = std::hypot(dx[suspect] - pred_x, dy[suspect] - pred_y);
  return miss > kConsistencyToleranceM + kConsistencyToleranceFraction * step_length ? suspect : -1;
}

enum class Method { kCast, kIpec };

}  // namespace fitcal::asoc
