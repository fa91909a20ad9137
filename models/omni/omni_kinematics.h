#pragma once
// The general holonomic robot on N >= 3 omni or mecanum (Swedish) wheels, on the model seam
// (kinematic_model.h). Palacin et al. 2022's three-wheel model is the case N = 3 with tangential
// drive directions and roller angle 0 (models/omni3/omni3_kinematics.h).
//
// Wheel i sits at distance R_i from the robot's centre at angle delta_i (robot frame, x forward,
// y left), has radius r_i, is driven in the direction phi_i = delta_i + beta_i (beta_i = +90 deg:
// tangential, counter-clockwise; the direction the robot is pushed when the wheel turns at a
// positive rate), and its rollers' axes make the angle gamma_i with that direction (0: omni
// wheel, +-45 deg: mecanum wheel).
//
// Rolling constraint (Siegwart, Nourbakhsh, Scaramuzza, Introduction to Autonomous Mobile
// Robots, 2nd ed., Sec. 3.2.3, Swedish wheel). The body velocity at the contact point is
//   v_c = (vx - omega R_i sin delta_i,  vy + omega R_i cos delta_i)
// and the wheel can only produce v_c = r_i w_i u_i + s e_i, u_i = (cos phi_i, sin phi_i) the drive
// direction and e_i the free direction of the roller (perpendicular to its axis), s free. Along
// the roller's axis a_i = (cos(phi_i + gamma_i), sin(phi_i + gamma_i)) the roller cannot move, so
// v_c . a_i = r_i w_i (u_i . a_i) = r_i w_i cos gamma_i, i.e. row i of the inverse kinematics
// w = J v, v = (vx, vy, omega):
//
//   w_i = [ cos(delta_i + beta_i + gamma_i),  sin(delta_i + beta_i + gamma_i),
//           R_i sin(beta_i + gamma_i) ] / (r_i cos gamma_i)
//
// (Siegwart's constraint [sin(a+b+g), -cos(a+b+g), -l cos(b+g)] R(theta) xi - r phi cos g = 0
// with alpha = delta_i, l = R_i and his wheel angle b = beta_i + 90 deg.)
// Palacin's convention is the case beta_i = 90 deg, gamma_i = 0: cos(delta + 90) = -sin delta,
// sin(delta + 90) = cos delta, sin 90 = 1, so row i = [-sin delta_i, cos delta_i, R_i] / r_i
// (Palacin Eq. 1 and 3). A mecanum wheel of ros2_controllers' layout (front left at (lx, ly),
// drive forward, gamma = -45 deg) gives w = (vx - vy - (lx + ly) omega) / r, their Eq. for the
// front-left wheel.
//
// Forward kinematics. For N = 3, J is square and v = J^-1 w (Palacin Eq. 4). For N > 3 the wheels
// over-determine the motion, and the body step is the least-squares solution
//   v = (J^T J)^-1 J^T w   (the pseudo-inverse of J).
// When the wheels agree (w in the range of J) it is exact. When they disagree, i.e. some wheel
// slips, no body motion explains all N rates; the pseudo-inverse picks the motion that minimises
// the sum of squared rate residuals |w - J v|^2, so slip is averaged: a slip s of wheel i moves
// the step by s times column i of F, shared with the wheels that did not slip, not rejected.
//
// Parameters: p = (R_1..R_N, r_1..r_N, delta_1..delta_N), Palacin Eq. 15's order for N = 3. The
// drive offsets beta_i and roller angles gamma_i are fixed geometry from the robot YAML, not
// fitted: a small change of beta_i + gamma_i moves row i much like a change of delta_i and R_i
// does, so fitting both would add directions the odometry cannot tell apart. A fitted delta_i
// turns wheel i about the centre, drive direction with it (Palacin's delta).
//
// Not every parameter is determinable for N > 3 (models/omni/omni_model.h holds a gauge).

#include <Eigen/Core>
#include <array>
#include <cmath>

#include "models/model_interface.h"

namespace fitcal {

// Fixed geometry of one wheel: drive direction relative to the radial line (beta_i) and roller
// angle (gamma_i), both in rad.
struct OmniWheelMount {
  double drive_offset_rad = M_PI / 2.0;  // tangential, counter-clockwise
  double roller_rad = 0.0;               // omni wheel
};

// The 3 x 3 inverse by the adjugate, templated so that Ceres differentiates it.
template <typename T>
Eigen::Matrix<T, 3, 3> Inverse3(const Eigen::Matrix<T, 3, 3>& m) {
  Eigen::Matrix<T, 3, 3> adj;
  adj(0, 0) = m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1);
  adj(0, 1) = m(0, 2) * m(2, 1) - m(0, 1) * m(2, 2);
  adj(0, 2) = m(0, 1) * m(1, 2) - m(0, 2) * m(1, 1);
  adj(1, 0) = m(1, 2) * m(2, 0) - m(1, 0) * m(2, 2);
  adj(1, 1) = m(0, 0) * m(2, 2) - m(0, 2) * m(2, 0);
  adj(1, 2) = m(0, 2) * m(1, 0) - m(0, 0) * m(1, 2);
  adj(2, 0) = m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0);
  adj(2, 1) = m(0, 1) * m(2, 0) - m(0, 0) * m(2, 1);
  adj(2, 2) = m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0);
  const T det = m(0, 0) * adj(0, 0) + m(0, 1) * adj(1, 0) + m(0, 2) * adj(2, 0);
  return adj * (T(1.0) / det);
}

template <int N>
struct OmniKinematics {
  static_assert(N >= 3, "a holonomic robot needs at least three wheels");
  static constexpr int kNumWheels = N;
  static constexpr int kNumChannels = N;
  static constexpr int kNumParameters = 3 * N;
  static constexpr int kDistanceIndex = 0;   // R_1..R_N
  static constexpr int kRadiusIndex = N;     // r_1..r_N
  static constexpr int kAngleIndex = 2 * N;  // delta_1..delta_N
  // The body step F w dt is linear in the rates: analytic final-pose Jacobian
  // (models/final_pose_jacobian.h).
  static constexpr FinalPoseJacobianKind kFinalPoseJacobianKind =
      FinalPoseJacobianKind::kLinearInChannels;

  template <typename T>
  using KinematicMatrixT = Eigen::Matrix<T, N, 3>;  // J: w = J v
  template <typename T>
  using ForwardMatrixT = Eigen::Matrix<T, 3, N>;  // pinv(J): v = F w

  std::array<OmniWheelMount, N> mount{};  // default: tangential omni wheels

  // J, row i as derived above.
  template <typename T>
  KinematicMatrixT<T> KinematicMatrix(const T* p) const {
    using std::cos;
    using std::sin;
    KinematicMatrixT<T> j;
    for (int i = 0; i < N; ++i) {
      const double beta_plus_gamma = mount[i].drive_offset_rad + mount[i].roller_rad;
      const T axis_angle = p[kAngleIndex + i] + beta_plus_gamma;
      const T scale = T(1.0 / std::cos(mount[i].roller_rad)) / p[kRadiusIndex + i];
      j(i, 0) = cos(axis_angle) * scale;
      j(i, 1) = sin(axis_angle) * scale;
      j(i, 2) = p[kDistanceIndex + i] * std::sin(beta_plus_gamma) * scale;
    }
    return j;
  }

  // F = J^-1 for N = 3, (J^T J)^-1 J^T for N > 3; once per replay.
  template <typename T>
  ForwardMatrixT<T> Prepare(const T* p) const {
    const KinematicMatrixT<T> j = KinematicMatrix(p);
    if constexpr (N == 3) {
      return Inverse3<T>(j);
    } else {
      const Eigen::Matrix<T, 3, 3> jtj = j.transpose() * j;
      return Inverse3<T>(jtj) * j.transpose();
    }
  }

  // The body-frame step F w dt of one encoder interval (Palacin Eq. 4 for N = 3).
  template <typename T, typename C>
  void BodyStep(const ForwardMatrixT<T>& f, const C* w, double dt, T* dx, T* dy, T* dtheta) const {
    T sx = f(0, 0) * w[0];
    T sy = f(1, 0) * w[0];
    T st = f(2, 0) * w[0];
    for (int i = 1; i < N; ++i) {
      sx += f(0, i) * w[i];
      sy += f(1, i) * w[i];
      st += f(2, i) * w[i];
    }
    *dx = sx * dt;
    *dy = sy * dt;
    *dtheta = st * dt;
  }

  // w = J v: any twist is drivable.
  bool ChannelsForTwist(const double* p, const Twist& twist, double* w) const {
    const Eigen::Vector3d v(twist.vx_m_s, twist.vy_m_s, twist.omega_rad_s);
    const Eigen::Matrix<double, N, 1> rates = KinematicMatrix(p) * v;
    for (int i = 0; i < N; ++i) w[i] = rates[i];
    return true;
  }
};

}  // namespace fitcal
