#pragma once
// The kinematics of an ASOC vehicle (Doebbler et al., models/asoc/asoc_model.h) on the model seam
// (models/kinematic_model.h): the multi-castor least-squares odometry of Doebbler Sec. III-B as
// the body step of one encoder interval, templated on the scalar.
//
// Parameters p (18): castor i's block [6 i, 6 i + 6) = (r_c, r_w1, r_w2, d_1, d_2, beta), the
// order of asoc::Vehicle::ToArray. The pivot layout (R_i, phi_i) is known geometry (Doebbler assume
// the pivot distance D known) and is held as data here, not fitted: it fixes the body frame's
// origin, orientation and length scale. (Each castor's r_c and beta are held by the model, for
// another reason: asoc_robot_model.cc.)
// Channels (9): castor by castor, wheel 1 rate, wheel 2 rate (rad/s), pivot angle gamma_i (rad, the
// mean of the interval's two readings; asoc_model.h kChannelsPerCastor).
//
// Body step, in the body frame at the interval's MIDDLE (B_mid, the start frame turned by dpsi/2):
//   1. each castor's pivot displacement: its motion (u, w, omega_c) from the wheel increments
//      (asoc_model.h), along the chord of its arc at the mid heading theta_i = gamma_i - beta_i
//      (Eq. 2: beta = measured - geometric angle); the channel's interval mean IS the mid reading;
//   2. Eq. 13-14 linearised about B_mid's heading (psi = 0 there):
//        dx_i = dx_c - s y_i,   dy_i = dy_c + s x_i,
//      solved by the least squares of Eq. 15 with the closed-form inverse of Eq. 18-21
//      (asoc_odometry.h SolveCastGeneral) over the castors used (CAST-n). For a rigid body the
//      pivots move from R(-dpsi/2) p_i to R(dpsi/2) p_i, i.e. by exactly 2 sin(dpsi/2) J p_i: about
//      the middle, Eq. 13-14 hold without the small-angle assumption, with s = 2 sin(dpsi/2);
//   3. dpsi = 2 asin(s / 2), and (dx_c, dy_c) turned by dpsi/2 back into the start frame, which the
//      generic replay (odometry/replay.h) rotates by the heading before the interval.
// The paper linearises about psi- (asoc-tables replayed so until asoc41); the two agree to second
// order in dpsi per interval, and this one replays a constant twist exactly.
//
// Variants (robot YAML `odometry:`, Doebbler Table II naming): CAST-i leaves castor i out (CAST-0
// uses all three); IPEC-i uses the other two castors, heading from the line through their pivots
// (Eq. 10; the least-squares s of two pivots is that line's turn) and the body placed by the lower-
// numbered (anchor) pivot's own displacement; the redundancy check (CAST-0 only) drops, for one
// interval, a castor whose displacement disagrees with the other two (asoc::InconsistentCastor),
// decided on the values, not on derivatives.

#include <array>
#include <cmath>
#include <string>

#include "models/asoc/asoc_model.h"
#include "models/asoc/asoc_odometry.h"
#include "models/model_interface.h"
#include "odometry/replay.h"

namespace fitcal {

namespace asoc {

// A pivot's body-frame velocity v + omega x p for a body twist.
inline std::array<double, 2> PivotVelocity(const Twist& twist, const PivotPosition& pivot) {
  return {twist.vx_m_s - twist.omega_rad_s * pivot.y_m(),
          twist.vy_m_s + twist.omega_rad_s * pivot.x_m()};
}

// The body-relative angle theta of a castor trailing its pivot in steady state, whose pivot moves
// at `pivot_velocity` (body frame) while the body turns at omega: the castor turns with the body
// (chi_dot = omega), so in its own frame the pivot moves at (u, w) = (sqrt(|v_p|^2 - w^2),
// r_c omega) (asoc_model.h), and c1 is v_p's direction turned back by atan2(w, u). *along = u.
// False when the pivot moves no faster than r_c |omega| (no steady angle exists).
inline bool TrailingCastorAngle(const std::array<double, 2>& pivot_velocity, double offset_m,
                                double omega_rad_s, double* theta_rad, double* along_m_s) {
  const double speed = std::hypot(pivot_velocity[0], pivot_velocity[1]);
  const double lateral = offset_m * omega_rad_s;
  if (!(std::abs(lateral) < speed)) return false;
  *along_m_s = std::sqrt(speed * speed - lateral * lateral);
  *theta_rad =
      std::atan2(pivot_velocity[1], pivot_velocity[0]) - std::atan2(lateral, *along_m_s);
  return true;
}

}  // namespace asoc

// Which of Doebbler's odometry algorithms the body step runs.
struct AsocOdometryOptions {
  asoc::Method method = asoc::Method::kCast;
  int excluded_castor = 0;  // 1-based castor left out (CAST-i / IPEC-i); 0 = none (CAST-0)
  bool redundancy_check = false;

  asoc::CastorMask castors() const { return asoc::MaskExcluding(excluded_castor); }
  // Parses "CAST-i" (i = 0..3) or "IPEC-i" (i = 1..3); false otherwise.
  static bool Parse(const std::string& name, AsocOdometryOptions* out);
  bool IsValid(std::string* error) const;
};

struct AsocKinematics {
  static constexpr int kNumParameters = asoc::kNumParameters;
  static constexpr int kNumChannels = asoc::kNumChannels;

  std::array<asoc::PivotPosition, asoc::kNumCastors> pivots{};
  AsocOdometryOptions odometry;

  template <typename T>
  using Prepared = std::array<T, kNumParameters>;

  template <typename T>
  Prepared<T> Prepare(const T* p) const {
    Prepared<T> out;
    for (int k = 0; k < kNumParameters; ++k) out[k] = p[k];
    return out;
  }

  // Steps 1-3 of the header. C is the channel scalar (double, or T under effects).
  template <typename T, typename C>
  FITCAL_ALWAYS_INLINE void BodyStep(const Prepared<T>& p, const C* values, double dt, T* dx, T* dy,
                                     T* dtheta) const {
    using std::asin;
    using std::cos;
    using std::sin;
    T px[asoc::kNumCastors], py[asoc::kNumCastors];
    for (int i = 0; i < asoc::kNumCastors; ++i) {
      const T* castor = p.data() + i * asoc::kParametersPerCastor;
      const C* v = values + i * asoc::kChannelsPerCastor;
      const asoc::CastorMotion<T> m = asoc::PivotMotionFromWheels(
          castor, T(v[asoc::kWheelAChannel] * dt), T(v[asoc::kWheelBChannel] * dt));
      asoc::PivotChord(m, T(v[asoc::kPivotChannel] - castor[asoc::kBiasIndex]), &px[i], &py[i]);
    }
    const asoc::CastorMask mask = UsedCastors(px, py);
    const asoc::BodyStep<T> mid = asoc::SolveCastGeneral(pivots, mask, T(0.0), px, py);
    T mid_dx = mid.dx_m, mid_dy = mid.dy_m;
    if (odometry.method == asoc::Method::kIpec) {
      const int a = AnchorCastor(mask);  // Eq. 13-14 for the anchor alone: it sets the translation
      mid_dx = px[a] + mid.dpsi_rad * pivots[a].y_m();
      mid_dy = py[a] - mid.dpsi_rad * pivots[a].x_m();
    }
    *dtheta = T(2.0) * asin(mid.dpsi_rad * 0.5);
    const T c = cos(*dtheta * 0.5), s = sin(*dtheta * 0.5);
    *dx = c * mid_dx - s * mid_dy;
    *dy = s * mid_dx + c * mid_dy;
  }

  // Channel values for a body twist with the castors in steady state: each castor trails its pivot
  // and turns with the body (chi_dot = omega), so its pivot moves at (u, w) = (|v_p| cos,
  // r_c omega) in its own frame (asoc_model.h); gamma_i = theta_i + beta_i. False when a pivot
  // moves slower than r_c |omega| (no steady castor angle exists).
  bool ChannelsForTwist(const double* p, const Twist& twist, double* values) const;

 private:
  template <typename T>
  asoc::CastorMask UsedCastors(const T* px, const T* py) const {
    asoc::CastorMask mask = odometry.castors();
    if (!odometry.redundancy_check) return mask;
    double x[asoc::kNumCastors], y[asoc::kNumCastors];
    for (int i = 0; i < asoc::kNumCastors; ++i) {
      x[i] = ScalarPart(px[i]);
      y[i] = ScalarPart(py[i]);
    }
    const int suspect = asoc::InconsistentCastor(pivots, 0.0, x, y);
    return suspect < 0 ? mask : mask & ~(1u << suspect);
  }
  static int AnchorCastor(asoc::CastorMask mask) {
    for (int i = 0; i < asoc::kNumCastors; ++i) {
      if ((mask >> i) & 1u) return i;
    }
    return 0;
  }
};

}  // namespace fitcal
