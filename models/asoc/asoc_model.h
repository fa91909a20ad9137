#pragma once
// The kinematic model of a vehicle driven by active split offset castors (ASOC), Doebbler, Davis,
// Junkins, Valasek, "Odometry and Calibration Methods for Multi-Castor Vehicles", Sec. II-III
// (seeds/000_d2ce87bdaf3d77db.txt).
//
// Frames and symbols (Doebbler Fig. 2 and 3):
//   N      world frame; the body frame B is at (x_c, y_c) with heading psi.
//   pivot i sits at body polar coordinates (R_i, phi_i): p_i = R_i (cos phi_i, sin phi_i).
//   theta_i  the true angle of castor i's frame C_i relative to B; the absolute castor heading is
//            chi_i = psi + theta_i. c1 = (cos chi, sin chi) is the castor's rolling direction,
//            c2 = (-sin chi, cos chi) points along the axle to the left.
//   gamma_i  the pivot encoder reading; beta_i = gamma_i - theta_i is its bias (Eq. 2 defines
//            beta as measured minus geometric angle), so theta_i = gamma_i - beta_i.
//   r_c      offset of the axle behind the pivot (the axle line is perpendicular to c1 at
//            distance r_c, on the -c1 side: a trailing castor).
//   r_w1,r_w2 wheel radii; d_1, d_2 the distances from the foot of that perpendicular to wheel 1
//            (on the +c2 side) and wheel 2 (on the -c2 side) along the axle. Sign s_1 = +1,
//            s_2 = -1 as in Eq. 9.
//
// Derivation of the pivot velocity from the wheel rates (no lateral slip, rolling without slip).
// Let the pivot move with world velocity v_p and the castor turn at chi_dot = omega_c. The contact
// point of wheel k is q_k = p + (-r_c) c1 + s_k d_k c2, rigidly attached to the castor, so
//   v_qk = v_p + omega_c perp(q_k - p) = v_p + omega_c (-r_c c2 - s_k d_k c1),
// with perp(c1) = c2, perp(c2) = -c1. Write u = v_p . c1 and w = v_p . c2. Then
//   no lateral slip (v_qk . c2 = 0):        w - r_c omega_c = 0
//   rolling         (v_qk . c1 = r_wk w_k): u - s_k d_k omega_c = r_wk w_k
// i.e. r_w1 w_1 = u - d_1 omega_c and r_w2 w_2 = u + d_2 omega_c, whence
//   omega_c = (r_w2 w_2 - r_w1 w_1) / (d_1 + d_2)
//   u       = (d_2 r_w1 w_1 + d_1 r_w2 w_2) / (d_1 + d_2)
//   w       = r_c omega_c.
// With both axles on one line (Doebbler's second assumption) the two lateral constraints are one,
// so two wheel rates fix the pivot's planar velocity and the castor's turn rate.
//
// Check against Eq. 4-7: rotating the body at psi_dot about a stationary pivot at distance D, a
// castor in steady state turns with the body (omega_c = psi_dot) and its pivot moves at speed
// D |psi_dot|. Then w = r_c psi_dot and u = D cos(Gamma) |psi_dot| with sin(Gamma) = r_c / D
// (Eq. 3): r_w1 w_1 = |psi_dot| (D cos Gamma + d_1) for CW (psi_dot < 0) and
// |psi_dot| (D cos Gamma - d_1) for CCW, exactly Eq. 4 and Eq. 6 (Eq. 5 and 7 for wheel 2).
//
// Everything here is templated on the scalar so that Ceres can differentiate through it.

#include <array>
#include <cmath>

namespace fitcal::asoc {

inline constexpr int kNumCastors = 3;
inline constexpr int kParametersPerCastor = 6;
inline constexpr int kNumParameters = kNumCastors * kParametersPerCastor;
// Offsets inside one castor's block of the flat parameter vector.
inline constexpr int kOffsetIndex = 0;       // r_c
inline constexpr int kWheelRadiusIndex = 1;  // r_w1, r_w2
inline constexpr int kWheelOffsetIndex = 3;  // d_1, d_2
inline constexpr int kBiasIndex = 5;         // beta

// The encoder channels of an ASOC vehicle on the model seam (models/asoc/asoc_kinematics.h), castor
// by castor: wheel 1 ("a") rate, wheel 2 ("b") rate (rad/s over an interval), pivot angle gamma_i
// (rad, the mean of the interval's two readings). Channel of castor i, kind k: 3 i + k.
inline constexpr int kChannelsPerCastor = 3;
inline constexpr int kNumChannels = kNumCastors * kChannelsPerCastor;
inline constexpr int kWheelAChannel = 0;
inline constexpr int kWheelBChannel = 1;
inline constexpr int kPivotChannel = 2;

// Where a pivot is on the body (known geometry: Doebbler assumes the pivot distance D known).
struct PivotPosition {
  double radius_m = 0.0;   // R_i
  double angle_rad = 0.0;  // phi_i
  double x_m() const { return radius_m * std::cos(angle_rad); }
  double y_m() const { return radius_m * std::sin(angle_rad); }
};

// The parameters a calibration estimates for one castor (Doebbler Sec. III-A).
struct CastorParameters {
  double offset_m = 0.0;                   // r_c
  std::array<double, 2> wheel_radius_m{};  // r_w1, r_w2
  std::array<double, 2> wheel_offset_m{};  // d_1, d_2
  double encoder_bias_rad = 0.0;           // beta

  void ToArray(double* p) const {
    p[kOffsetIndex] = offset_m;
    p[kWheelRadiusIndex] = wheel_radius_m[0];
    p[kWheelRadiusIndex + 1] = wheel_radius_m[1];
    p[kWheelOffsetIndex] = wheel_offset_m[0];
    p[kWheelOffsetIndex + 1] = wheel_offset_m[1];
    p[kBiasIndex] = encoder_bias_rad;
  }
  static CastorParameters FromArray(const double* p) {
    CastorParameters c;
    c.offset_m = p[kOffsetIndex];
    c.wheel_radius_m = {p[kWheelRadiusIndex], p[kWheelRadiusIndex + 1]};
    c.wheel_offset_m = {p[kWheelOffsetIndex], p[kWheelOffsetIndex + 1]};
    c.encoder_bias_rad = p[kBiasIndex];
    return c;
  }
};

// A whole vehicle: pivot layout (fixed) and the calibrated castor parameters.
struct Vehicle {
  std::array<PivotPosition, kNumCastors> pivots{};
  std::array<CastorParameters, kNumCastors> castors{};

  // Flat castor parameters, castor i at [6 i, 6 i + 6): the block a solver sees.
  std::array<double, kNumParameters> ToArray() const {
    std::array<double, kNumParameters> p{};
    for (int i = 0; i < kNumCastors; ++i) castors[i].ToArray(&p[i * kParametersPerCastor]);
    return p;
  }
  void SetFromArray(const double* p) {
    for (int i = 0; i < kNumCastors; ++i) {
      castors[i] = CastorParameters::FromArray(p + i * kParametersPerCastor);
    }
  }
  // Distance between pivots i and j (Doebbler's D).
  double PivotDistance(int i, int j) const {
    return std::hypot(pivots[i].x_m() - pivots[j].x_m(), pivots[i].y_m() - pivots[j].y_m());
  }
};

// Motion of one castor in its own frame over an interval or per unit time.
template <typename T>
struct CastorMotion {
  T along;    // u: pivot motion along c1 (m or m/s)
  T lateral;  // w: pivot motion along c2
  T turn;     // omega_c: castor rotation in the world (rad or rad/s)
};

// Wheel rates (or wheel angle increments) -> pivot motion in the castor frame (derivation above).
// p points at one castor's block of kParametersPerCastor values.
template <typename T>
CastorMotion<T> PivotMotionFromWheels(const T* p, const T& wheel_1, const T& wheel_2) {
  const T& r_c = p[kOffsetIndex];
  const T& r_w1 = p[kWheelRadiusIndex];
  const T& r_w2 = p[kWheelRadiusIndex + 1];
  const T& d_1 = p[kWheelOffsetIndex];
  const T& d_2 = p[kWheelOffsetIndex + 1];
  const T roll_1 = r_w1 * wheel_1;
  const T roll_2 = r_w2 * wheel_2;
  const T inv_axle = T(1.0) / (d_1 + d_2);
  CastorMotion<T> m;
  m.turn = (roll_2 - roll_1) * inv_axle;
  m.along = (d_2 * roll_1 + d_1 * roll_2) * inv_axle;
  m.lateral = r_c * m.turn;
  return m;
}

// The inverse: wheel rates that make the castor's pivot move at (u, w) in the castor frame. The
// castor's turn rate is then w / r_c (it cannot be chosen independently: castor dynamics).
inline std::array<double, 2> WheelRatesFromPivotMotion(const CastorParameters& c, double along,
                                                       double lateral) {
  const double turn = lateral / c.offset_m;
  return {(along - c.wheel_offset_m[0] * turn) / c.wheel_radius_m[0],
          (along + c.wheel_offset_m[1] * turn) / c.wheel_radius_m[1]};
}

// The chord of the pivot's arc over one interval: with constant rates the castor turns by
// omega_c and the pivot runs along an arc whose chord is the motion (u, w) rotated to the castor's
// heading at the interval's middle and shortened by sinc(omega_c / 2). Borenstein's midpoint
// odometry, adapted to the pivot offset as Doebbler Sec. III-B describes.
template <typename T>
void PivotChord(const CastorMotion<T>& m, const T& mid_heading_rad, T* dx_m, T* dy_m) {
  using std::abs;
  using std::cos;
  using std::sin;
  const T half = m.turn * 0.5;
  // sinc(half) by its series below 1e-4 rad (exact to 1e-17 there), by sin/x above.
  const T chord = abs(half) < T(1e-4) ? T(1.0) - half * half / 6.0 : sin(half) / half;
  const T c = cos(mid_heading_rad) * chord;
  const T s = sin(mid_heading_rad) * chord;
  *dx_m = c * m.along - s * m.lateral;
  *dy_m = s * m.along + c * m.lateral;
}

}  // namespace fitcal::asoc
