#pragma once
// A planar pose (x, y, theta) templated on the scalar, so the same code runs on double and on
// ceres::Jet. Frames follow Palacin et al. 2022, Fig. 2: x, y in the world frame (m), theta the
// heading of the robot's X_R axis from the world X_W axis (rad, counter-clockwise positive).

#include <cmath>

namespace fitcal {

template <typename T>
struct Pose2 {
  T x{0.0};
  T y{0.0};
  T theta{0.0};
};

using Pose2d = Pose2<double>;

// Wraps an angle to [-pi, pi). Written with floor so that it also works on ceres::Jet (the
// derivative of a wrap is 1 everywhere it is defined).
template <typename T>
T WrapAngle(const T& angle_rad) {
  using std::floor;
  const double two_pi = 2.0 * M_PI;
  return angle_rad - two_pi * floor((angle_rad + M_PI) / two_pi);
}

// The value of a scalar without its derivatives: itself for double, the real part `a` of a
// ceres::Jet (found by overload, so odometry/ needs no Ceres header). For decisions that must not
// depend on derivatives, such as which series to use.
inline double ScalarPart(double v) { return v; }
template <typename JetT>
double ScalarPart(const JetT& v) {
  return v.a;
}

inline double DegToRad(double angle_deg) { return angle_deg * (M_PI / 180.0); }
inline double RadToDeg(double angle_rad) { return angle_rad * (180.0 / M_PI); }

}  // namespace fitcal
