#pragma once
// A tricycle (one steered, driven wheel in front, a passive rear axle: forklifts, tuggers; the
// kinematics of ros2_controllers' tricycle_controller) on the model seam (kinematic_model.h).
//
// Parameters p = (r, L, phi_0):
//   r      radius of the traction (steered and driven) wheel (m)
//   L      wheelbase: traction wheel contact point to the rear axle's centre, along the body x
//          axis (m)
//   phi_0  steering offset: the true steering angle is phi + phi_0, phi the measured one (rad,
//          counter-clockwise positive, 0 = straight ahead)
// Channels: 0 the traction wheel's mean rate w over the interval (rad/s), 1 the steering angle
// phi over the interval (rad; the loader gives the mean of the readings at the interval's ends,
// the midpoint rule, odometry/robot.h).
//
// Body motion, reference point at the rear axle's centre (the ground truth of OptiOdom's tricycle
// is that point, the midpoint of the rear wheels' markers). Rigid body: the velocity of the
// traction wheel's contact point (L, 0) is (vx - omega * 0, vy + omega L). The rear wheels do not
// slip sideways, so vy = 0 at the rear axle; the traction wheel rolls along its own heading
// phi' = phi + phi_0 with speed v = r w:
//   (vx, omega L) = v (cos phi', sin phi')   =>   vx = v cos phi',  vy = 0,  omega = v sin phi' / L
// Over one encoder interval of length dt the wheel rolls d = r w dt and the body step is
//   dx = d cos(phi + phi_0),   dy = 0,   dtheta = d sin(phi + phi_0) / L            (T1)
// (first order in the interval, as Palacin Eq. 4 for omni3; the generic replay rotates the step
// by the heading before it). For constant steering this is an arc of radius
//   rho = L / tan(phi + phi_0)                                                      (T2)
// traced by the rear axle's centre (dx / dtheta = L cos phi' / sin phi').
//
// Identifiability: r scales the travelled distance (position), r / L scales the turning, and
// phi_0 is separated from L by driving at several steering angles, both ways (a circle at one
// steering angle in one direction sees only sin(phi + phi_0) / L, one number). No gauge: all three
// are free when the runs turn both ways at two or more steering angles AND end away from where
// they started. The final pose of a closed path (whole circles, a closed square) is the same for
// every common scale k of (r, L): the heading sees r / L, the path's shape scales with k, a
// closed shape stays closed. OptiOdom's real runs are nearly closed (2.1 circles, squares ending
// 0.3 m off): there r is known to 1.5 % only (tests/tricycle_test.cc), segments or open paths pin
// it down (models/tricycle/tricycle_trajectories.h).

#include <cmath>

#include "models/model_interface.h"
#include "odometry/sin_cos.h"

namespace fitcal {

// kHasGain: the robot YAML declares `steering_gain` (k below), a fourth parameter; without it the
// parameters are the three above and k = 1 (the robots and outputs of before, unchanged).
//   phi' = k phi + phi_0                                                             (T3)
// Why k: an absolute encoder on the steering column reads the column's angle, and a linkage or a
// gear between column and wheel turns the wheel a fraction of it. k and L are told apart only by
// the shape of the turns (sin and cos of phi' in T1 are not linear in k phi): runs at large
// steering angles, both ways, determine both; near straight driving sees k / L alone.
template <bool kHasGain>
struct TricycleKinematicsT {
  static constexpr int kNumParameters = kHasGain ? 4 : 3;
  static constexpr int kNumChannels = 2;
  static constexpr int kRadiusIndex = 0;
  static constexpr int kWheelbaseIndex = 1;
  static constexpr int kSteeringOffsetIndex = 2;
  static constexpr int kSteeringGainIndex = 3;  // with kHasGain only
  static constexpr int kTractionChannel = 0;
  static constexpr int kSteeringChannel = 1;
  // |vy| above this (m/s) is a twist a tricycle cannot drive (ChannelsForTwist).
  static constexpr double kMaxSidewaysSpeed_m_s = 1e-9;

  template <typename T>
  struct Prepared {
    T radius_m;
    T inverse_wheelbase_per_m;
    T steering_offset_rad;
    T steering_gain;
  };

  template <typename T>
  static Prepared<T> Prepare(const T* p) {
    return {p[kRadiusIndex], T(1.0) / p[kWheelbaseIndex], p[kSteeringOffsetIndex],
            kHasGain ? p[kSteeringGainIndex] : T(1.0)};
  }

  // (T1) with (T3). C is the channel scalar: double for recorded channels, T when an effect
  // makes the channel values depend on parameters.
  template <typename T, typename C>
  static void BodyStep(const Prepared<T>& k, const C* values, double dt, T* dx, T* dy, T* dtheta) {
    const T distance_m = k.radius_m * values[kTractionChannel] * dt;
    T steering_rad = k.steering_offset_rad;
    if constexpr (kHasGain) {
      steering_rad += k.steering_gain * values[kSteeringChannel];
    } else {
      steering_rad += values[kSteeringChannel];
    }
    T sin_steering, cos_steering;
    // The steering reading holds for most samples (sin_cos.h): libm once per new angle.
    SinCosOfRepeatedAngle(steering_rad, &sin_steering, &cos_steering);
    *dx = distance_m * cos_steering;
    *dy = T(0.0);
    *dtheta = distance_m * sin_steering * k.inverse_wheelbase_per_m;
  }

  // Inverse of (T1) per unit time: the traction wheel's velocity in the body frame is
  // (vx, omega L), so v = |(vx, omega L)| and phi' = its direction. A tricycle cannot move
  // sideways at the rear axle: vy != 0 returns false.
  // Branch: forward and pure rotation (vx >= 0) steer within [-pi/2, pi/2] and roll forward,
  //   phi' = atan2(omega L, vx),  v = +sqrt(vx^2 + (omega L)^2);
  // reverse (vx < 0) keeps the wheel within (-pi/2, pi/2) and rolls it backwards,
  //   phi' = atan2(-omega L, -vx),  v = -sqrt(vx^2 + (omega L)^2)
  // (the other branch, phi' beyond +-pi/2 with v > 0, is the same motion, but real steering
  // stops at about +-90 deg). Then phi = (phi' - phi_0) / k and w = v / r. At rest phi' = 0.
  static bool ChannelsForTwist(const double* p, const Twist& twist, double* values) {
    if (std::abs(twist.vy_m_s) > kMaxSidewaysSpeed_m_s) return false;
    const double lateral_m_s = twist.omega_rad_s * p[kWheelbaseIndex];  // omega L
    const double speed_m_s = std::hypot(twist.vx_m_s, lateral_m_s);
    const bool reverse = twist.vx_m_s < 0.0;
    const double steering_rad =
        reverse ? std::atan2(-lateral_m_s, -twist.vx_m_s) : std::atan2(lateral_m_s, twist.vx_m_s);
    const double gain = kHasGain ? p[kSteeringGainIndex] : 1.0;
    if (gain == 0.0) return false;
    values[kTractionChannel] = (reverse ? -speed_m_s : speed_m_s) / p[kRadiusIndex];
    values[kSteeringChannel] = (steering_rad - p[kSteeringOffsetIndex]) / gain;
    return true;
  }
};

using TricycleKinematics = TricycleKinematicsT<false>;
using TricycleGainKinematics = TricycleKinematicsT<true>;

}  // namespace fitcal
