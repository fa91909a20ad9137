#pragma once
// The kinematic model of a three-wheeled omnidirectional robot, Palacin et al. 2022, Sec. 2.2.
//
// Nine physical parameters, stored flat in the order of Palacin Eq. 15 so that a solver sees one
// parameter block:   p = (R_a, R_b, R_c,  r_a, r_b, r_c,  delta_a, delta_b, delta_c)
//   R_i     distance from the robot centre to wheel i (m)
//   r_i     radius of wheel i (m)
//   delta_i angular position of wheel i in the robot frame (rad inside the code)
// Wheel i turns at w_i (rad/s); Eq. 1 with the robot-frame velocity (vx, vy, omega):
//   w_i * r_i = -sin(delta_i) vx + cos(delta_i) vy + R_i omega.
//
// Everything here is templated on the scalar so that Ceres can differentiate through it.

#include <Eigen/Core>
#include <array>
#include <cmath>

namespace fitcal::omni3 {

inline constexpr int kNumWheels = 3;
inline constexpr int kNumParameters = 9;
// Offsets of each parameter group in the flat vector.
inline constexpr int kDistanceIndex = 0;  // R_a..R_c
inline constexpr int kRadiusIndex = 3;    // r_a..r_c
inline constexpr int kAngleIndex = 6;     // delta_a..delta_c

template <typename T>
using Matrix3 = Eigen::Matrix<T, 3, 3>;

// The nine parameters as named fields; the flat form is ToArray()/FromArray().
struct Parameters {
  std::array<double, kNumWheels> distance_m{};
  std::array<double, kNumWheels> radius_m{};
  std::array<double, kNumWheels> angle_rad{};

  std::array<double, kNumParameters> ToArray() const {
    std::array<double, kNumParameters> p{};
    for (int i = 0; i < kNumWheels; ++i) {
      p[kDistanceIndex + i] = distance_m[i];
      p[kRadiusIndex + i] = radius_m[i];
      p[kAngleIndex + i] = angle_rad[i];
    }
    return p;
  }
  static Parameters FromArray(const double* p) {
    Parameters out;
    for (int i = 0; i < kNumWheels; ++i) {
      out.distance_m[i] = p[kDistanceIndex + i];
      out.radius_m[i] = p[kRadiusIndex + i];
      out.angle_rad[i] = p[kAngleIndex + i];
    }
    return out;
  }
};

// Compact kinematic matrix M, Palacin Eq. 3: w = M * v_robot, row i = [-sin d_i, cos d_i, R_i] /
// r_i.
template <typename T>
Matrix3<T> KinematicMatrix(const T* p) {
  using std::cos;
  using std::sin;
  Matrix3<T> m;
  for (int i = 0; i < kNumWheels; ++i) {
    const T& distance = p[kDistanceIndex + i];
    const T& radius = p[kRadiusIndex + i];
    const T& angle = p[kAngleIndex + i];
    m(i, 0) = -sin(angle) / radius;
    m(i, 1) = cos(angle) / radius;
    m(i, 2) = distance / radius;
  }
  return m;
}

// Determinant term of Palacin Eq. 6 (up to the factor 1/(r_a r_b r_c)); zero when the three
// wheel directions cannot span the plane's velocities (a degenerate robot).
template <typename T>
T InverseKinematicDenominator(const T* p) {
  using std::sin;
  const T* R = p + kDistanceIndex;
  const T* d = p + kAngleIndex;
  return R[0] * sin(d[1] - d[2]) - R[1] * sin(d[0] - d[2]) + R[2] * sin(d[0] - d[1]);
}

// M^-1 in closed form, Palacin Eq. 6: v_robot = M^-1 * w.
template <typename T>
Matrix3<T> InverseKinematicMatrix(const T* p) {
  using std::cos;
  using std::sin;
  const T* R = p + kDistanceIndex;
  const T* r = p + kRadiusIndex;
  const T* d = p + kAngleIndex;
  const T inv_den = T(1.0) / InverseKinematicDenominator(p);
  Matrix3<T> m;
  m(0, 0) = r[0] * (R[1] * cos(d[2]) - R[2] * cos(d[1]));
  m(0, 1) = -r[1] * (R[0] * cos(d[2]) - R[2] * cos(d[0]));
  m(0, 2) = r[2] * (R[0] * cos(d[1]) - R[1] * cos(d[0]));
  m(1, 0) = r[0] * (R[1] * sin(d[2]) - R[2] * sin(d[1]));
  m(1, 1) = -r[1] * (R[0] * sin(d[2]) - R[2] * sin(d[0]));
  m(1, 2) = r[2] * (R[0] * sin(d[1]) - R[1] * sin(d[0]));
  m(2, 0) = r[0] * sin(d[1] - d[2]);
  m(2, 1) = -r[1] * sin(d[0] - d[2]);
  m(2, 2) = r[2] * sin(d[0] - d[1]);
  return m * inv_den;
}

}  // namespace fitcal::omni3
