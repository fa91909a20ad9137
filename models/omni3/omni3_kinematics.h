#pragma once
// Palacin et al. 2022 on the model seam (kinematic_model.h): nine parameters in the order of
// Eq. 15, p = (R_a, R_b, R_c, r_a, r_b, r_c, delta_a, delta_b, delta_c), the body step of one
// encoder interval dt M^-1 w (Eq. 4) with M^-1 in the closed form of Eq. 6
// (models/omni3/omni3_parameters.h), and the inverse kinematics w = M v (Eq. 1 and 3).

#include "models/model_interface.h"
#include "models/omni3/omni3_parameters.h"
#include "odometry/replay.h"

namespace fitcal {

struct Omni3Kinematics {
  static constexpr int kNumParameters = omni3::kNumParameters;
  static constexpr int kNumChannels = omni3::kNumWheels;
  // The body step M^-1 w dt (Eq. 4) is linear in the rates: analytic final-pose Jacobian
  // (models/final_pose_jacobian.h).
  static constexpr FinalPoseJacobianKind kFinalPoseJacobianKind =
      FinalPoseJacobianKind::kLinearInChannels;

  template <typename T>
  static omni3::Matrix3<T> Prepare(const T* p) {
    return omni3::InverseKinematicMatrix(p);
  }

  // Eq. 4: the robot-frame step M^-1 w dt.
  template <typename T, typename C>
  FITCAL_ALWAYS_INLINE static void BodyStep(const omni3::Matrix3<T>& m_inv, const C* w, double dt,
                                            T* dx, T* dy, T* dtheta) {
    *dx = (m_inv(0, 0) * w[0] + m_inv(0, 1) * w[1] + m_inv(0, 2) * w[2]) * dt;
    *dy = (m_inv(1, 0) * w[0] + m_inv(1, 1) * w[1] + m_inv(1, 2) * w[2]) * dt;
    *dtheta = (m_inv(2, 0) * w[0] + m_inv(2, 1) * w[1] + m_inv(2, 2) * w[2]) * dt;
  }

  // Eq. 1: w = M (vx, vy, omega); any twist is drivable.
  static bool ChannelsForTwist(const double* p, const Twist& twist, double* w) {
    const Eigen::Vector3d v(twist.vx_m_s, twist.vy_m_s, twist.omega_rad_s);
    const Eigen::Vector3d rates = omni3::KinematicMatrix(p) * v;
    for (int i = 0; i < 3; ++i) w[i] = rates[i];
    return true;
  }
};

}  // namespace fitcal
