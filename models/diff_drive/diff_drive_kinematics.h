#pragma once
// A differential-drive robot on the model seam (kinematic_model.h): two driven wheels on one
// axle, the body frame's x axis forward, y to the left, theta counter-clockwise (odometry/pose2.h).
//
// Parameters, in the robot YAML's wheel order (= the encoder channels' order):
//   p = (r_<wheel 0>, r_<wheel 1>, b)   wheel radii (m) and the wheel separation b (m)
// Which of the two channels is the right wheel is a template argument (kRightChannel = 0 when the
// YAML lists the right wheel first, as OptiOdom's recordings and the example YAML do); the YAML
// reader picks the instantiation from each wheel's side (diff_drive_model.h).
//
// Channels: wheel rates w (rad/s), positive when the wheel drives the robot forward.
//
// Body step of one encoder interval (Borenstein & Feng 1996, Sec. 2): the wheel distances
// d_i = r_i w_i dt, the distance of the axle's midpoint and the turn
//   s = (d_R + d_L) / 2,   dtheta = (d_R - d_L) / b
// (the right wheel running further turns the robot left, counter-clockwise). With the rates
// constant over the interval the midpoint moves on an arc of length s, and its displacement in
// the body frame at the interval's start is the arc's chord:
//   dx = s sin(dtheta) / dtheta,   dy = s (1 - cos(dtheta)) / dtheta
// i.e. length s sinc(dtheta/2) in the direction dtheta/2. To first order this is Borenstein &
// Feng's dx = s, dy = 0; unlike it, it puts the pose on the arc exactly (no O(dtheta) drift of
// the replay on curves), which is what the generic replay (odometry/replay.h) expects of a body
// step. Near dtheta = 0 both ratios use their Taylor series (also on ceres::Jet).
//
// Inverse kinematics: a differential drive cannot move sideways; for (vx, 0, omega)
//   w_R = (vx + omega b / 2) / r_R,   w_L = (vx - omega b / 2) / r_L.

#include <ceres/jet.h>

#include <cmath>

#include "models/model_interface.h"
#include "odometry/pose2.h"
#include "odometry/sin_cos.h"

namespace fitcal {

namespace diff_drive {

inline constexpr int kNumWheels = 2;
inline constexpr int kNumParameters = 3;
inline constexpr int kSeparationIndex = 2;

// Below this |dtheta| the chord ratios use series truncated after the a^6 term: error < a^8/9!
// < 3e-22 relative, far below rounding.
inline constexpr double kChordSeriesMaxAngle = 1e-2;

// sin(a) / a and (1 - cos(a)) / a, on double or ceres::Jet.
template <typename T>
void ChordRatios(const T& a, T* sin_over_a, T* one_minus_cos_over_a) {
  if (std::abs(ScalarPart(a)) < kChordSeriesMaxAngle) {
    const T a2 = a * a;
    *sin_over_a = 1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0)));
    *one_minus_cos_over_a =
        a * (0.5 + a2 * (-1.0 / 24.0 + a2 * (1.0 / 720.0 + a2 * (-1.0 / 40320.0))));
    return;
  }
  T sin_a, cos_a;
  SinCos(a, &sin_a, &cos_a);
  *sin_over_a = sin_a / a;
  *one_minus_cos_over_a = (1.0 - cos_a) / a;
}

// The same on ceres::Jet, written out on the value and each derivative. Why: the template above on
// Jets was a third of a diff drive's fits (perf of `generalise --optiodom` on the OptiOdom diff
// drive: 35 %), most of it in Eigen's 3-vector products that GCC left out of line. Every number is
// the template's to the bit: the products and sums ceres/jet.h's operators make, in their order
// (f * g = (f.a g.a, f.a g.v + f.v g.a), s + f = (f.a + s, f.v), f * s = (f.a s, f.v s),
// f / g = (f.a / g.a, (f.v - (f.a / g.a) g.v) / g.a) with 1 / g.a taken once;
// FinalPoseJacobian.ChordRatiosAreTheJetOperatorsBitForBit checks both branches). Inlined: the
// hand-written step Jacobian calls it on every sample of a small turn, and out of line the call
// was 7 % of a differential drive's fit (perf of the 97-run fit with clock offsets).
template <int N>
[[gnu::always_inline]] inline void ChordRatios(const ceres::Jet<double, N>& a,
                                               ceres::Jet<double, N>* sin_over_a,
                                               ceres::Jet<double, N>* one_minus_cos_over_a) {
  if (std::abs(a.a) < kChordSeriesMaxAngle) {
    // a2 = a * a; then Horner, each level (c + a2 * inner) a Jet product of a2 and the level below.
    const double a2 = a.a * a.a;
    const double s1 = a2 * (-1.0 / 5040.0) + 1.0 / 120.0;
    const double s2 = a2 * s1 + -1.0 / 6.0;
    const double c1 = a2 * (-1.0 / 40320.0) + 1.0 / 720.0;
    const double c2 = a2 * c1 + -1.0 / 24.0;
    const double c3 = a2 * c2 + 0.5;
    sin_over_a->a = a2 * s2 + 1.0;
    one_minus_cos_over_a->a = a.a * c3;
    for (int i = 0; i < N; ++i) {
      const double a2_v = a.a * a.v[i] + a.v[i] * a.a;
      const double s1_v = a2_v * (-1.0 / 5040.0);
      const double s2_v = a2 * s1_v + a2_v * s1;
      sin_over_a->v[i] = a2 * s2_v + a2_v * s2;
      const double c1_v = a2_v * (-1.0 / 40320.0);
      const double c2_v = a2 * c1_v + a2_v * c1;
      const double c3_v = a2 * c2_v + a2_v * c2;
      one_minus_cos_over_a->v[i] = a.a * c3_v + a.v[i] * c3;
    }
    return;
  }
  const double s = std::sin(a.a);
  const double c = std::cos(a.a);
  const double inverse = 1.0 / a.a;
  const double sin_ratio = s * inverse;
  const double cos_ratio = (1.0 - c) * inverse;
  sin_over_a->a = sin_ratio;
  one_minus_cos_over_a->a = cos_ratio;
  for (int i = 0; i < N; ++i) {
    // sin(a) = (s, c a.v), cos(a) = (c, -s a.v), 1 - cos(a) = (1 - c, -(-s a.v)).
    sin_over_a->v[i] = (c * a.v[i] - sin_ratio * a.v[i]) * inverse;
    one_minus_cos_over_a->v[i] = (-(-s * a.v[i]) - cos_ratio * a.v[i]) * inverse;
  }
}

}  // namespace diff_drive

template <int kRightChannel>
struct DiffDriveKinematicsT {
  static_assert(kRightChannel == 0 || kRightChannel == 1, "two channels");
  static constexpr int kNumParameters = diff_drive::kNumParameters;
  static constexpr int kNumChannels = diff_drive::kNumWheels;
  static constexpr int kRight = kRightChannel;
  static constexpr int kLeft = 1 - kRightChannel;
  // The chord makes the step nonlinear in the rates: Jets on each step, poses in double
  // (models/final_pose_jacobian.h).
  static constexpr FinalPoseJacobianKind kFinalPoseJacobianKind =
      FinalPoseJacobianKind::kPerSampleStep;

  template <typename T>
  struct Prepared {
    T r_right;
    T r_left;
    T inv_separation;
  };

  template <typename T>
  static Prepared<T> Prepare(const T* p) {
    return {p[kRight], p[kLeft], 1.0 / p[diff_drive::kSeparationIndex]};
  }

  template <typename T, typename C>
  static void BodyStep(const Prepared<T>& k, const C* w, double dt, T* dx, T* dy, T* dtheta) {
    const T d_right = k.r_right * w[kRight] * dt;
    const T d_left = k.r_left * w[kLeft] * dt;
    const T s = 0.5 * (d_right + d_left);
    *dtheta = (d_right - d_left) * k.inv_separation;
    T sin_over_a, one_minus_cos_over_a;
    diff_drive::ChordRatios(*dtheta, &sin_over_a, &one_minus_cos_over_a);
    *dx = s * sin_over_a;
    *dy = s * one_minus_cos_over_a;
  }

  // G = d(dx, dy, dtheta)/dp of BodyStep, by hand (the final-pose and segment Jacobians,
  // models/final_pose_jacobian.h PerSampleSums; cheaper than BodyStep on Jets of all P), given
  // the step (dx, dy) BodyStep made. With u_i = w_i dt, s = (r_R u_R + r_L u_L) / 2,
  // a = (r_R u_R - r_L u_L) / b and the chord ratios f(a) = sin(a) / a, g(a) = (1 - cos(a)) / a:
  //   ds/dr_R = u_R / 2, ds/dr_L = u_L / 2, ds/db = 0;  da/dr_R = u_R / b, da/dr_L = -u_L / b,
  //   da/db = -a / b;  d dx = f ds + s f'(a) da,  d dy = g ds + s g'(a) da,  d dtheta = da.
  // f and g are the step's own (dx / s, dy / s), and with cos(a) = 1 - a g, sin(a) = a f
  //   f'(a) = (1 - a g - f) / a,   g'(a) = f - g / a,
  // no second sine (the difference loses < 1e-11 relative at |a| = 1e-2). Below the series' bound
  // (or when s = 0, where dx / s is undefined) a Jet of one dimension through ChordRatios.
  static void StepJacobian(const double* p, const double* w, double dt, double dx, double dy,
                           double g[3][diff_drive::kNumParameters]) {
    const double u_right = w[kRight] * dt, u_left = w[kLeft] * dt;
    const double inv_separation = 1.0 / p[diff_drive::kSeparationIndex];
    const double s = 0.5 * (p[kRight] * u_right + p[kLeft] * u_left);
    const double a = (p[kRight] * u_right - p[kLeft] * u_left) * inv_separation;
    double f, h, df, dh;
    if (std::abs(a) < diff_drive::kChordSeriesMaxAngle || s == 0.0) {
      ceres::Jet<double, 1> f_jet, h_jet;
      diff_drive::ChordRatios(ceres::Jet<double, 1>(a, 0), &f_jet, &h_jet);
      f = f_jet.a, h = h_jet.a, df = f_jet.v[0], dh = h_jet.v[0];
    } else {
      f = dx / s, h = dy / s;
      df = (1.0 - a * h - f) / a;
      dh = f - h / a;
    }
    double ds[diff_drive::kNumParameters] = {}, da[diff_drive::kNumParameters] = {};
    ds[kRight] = 0.5 * u_right;
    ds[kLeft] = 0.5 * u_left;
    da[kRight] = u_right * inv_separation;
    da[kLeft] = -u_left * inv_separation;
    da[diff_drive::kSeparationIndex] = -a * inv_separation;
    for (int j = 0; j < diff_drive::kNumParameters; ++j) {
      g[0][j] = f * ds[j] + s * df * da[j];
      g[1][j] = h * ds[j] + s * dh * da[j];
      g[2][j] = da[j];
    }
  }

  static bool ChannelsForTwist(const double* p, const Twist& twist, double* w) {
    if (twist.vy_m_s != 0.0) return false;
    const double half_turn = 0.5 * twist.omega_rad_s * p[diff_drive::kSeparationIndex];
    w[kRight] = (twist.vx_m_s + half_turn) / p[kRight];
    w[kLeft] = (twist.vx_m_s - half_turn) / p[kLeft];
    return true;
  }
};

// The right wheel first (OptiOdom's recordings, kDiffDriveExampleYaml).
using DiffDriveKinematics = DiffDriveKinematicsT<0>;

}  // namespace fitcal
