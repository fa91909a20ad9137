#pragma once
// Dead reckoning of a three-wheeled omni robot, Palacin et al. 2022 Eq. 4:
//   pose(k) = pose(k-1) + dt_k * R(theta(k-1))^-1 * M^-1 * w(k)
// with R^-1 of Eq. 5 and M^-1 of Eq. 6 (omni3_model.h). Templated on the scalar: the Ceres fit
// differentiates through it with ceres::Jet, everything else runs it on double.
//
// Speed: sin/cos of the heading at every sample would dominate the loop, so the heading's unit
// vector (c, s) is advanced by a rotation of dtheta_k per sample, using a short Taylor series for
// the small per-sample angle, and recomputed exactly from theta every kReanchorInterval samples so
// rounding cannot accumulate. The result equals Eq. 4 to rounding (tests/omni3_replay_test.cc).

#include <cmath>
#include <cstddef>

#include "odometry/omni3_model.h"
#include "odometry/pose2.h"
#include "odometry/wheel_samples.h"

namespace fitcal::omni3 {

namespace internal {

inline constexpr std::size_t kReanchorInterval = 256;
// Below this per-sample rotation (rad) the degree-10/11 Taylor series of cos/sin is exact to
// below 1e-17; above it (never at sane sample rates) the library functions are used.
inline constexpr double kSeriesMaxAngle = 0.2;

template <typename T>
inline void CosSinOfSmallAngle(const T& a, T* c, T* s) {
  using std::abs;
  using std::cos;
  using std::sin;
  if (abs(a) < T(kSeriesMaxAngle)) {
    const T a2 = a * a;
    *c = T(1.0) + a2 * (T(-1.0 / 2) + a2 * (T(1.0 / 24) + a2 * (T(-1.0 / 720) +
                 a2 * (T(1.0 / 40320) + a2 * T(-1.0 / 3628800)))));
    *s = a * (T(1.0) + a2 * (T(-1.0 / 6) + a2 * (T(1.0 / 120) + a2 * (T(-1.0 / 5040) +
                       a2 * (T(1.0 / 362880) + a2 * T(-1.0 / 39916800))))));
  } else {
    *c = cos(a);
    *s = sin(a);
  }
}

struct NoVisit {
  template <typename T>
  void operator()(std::size_t, const Pose2<T>&) const {}
};

}  // namespace internal

// Replays samples[0..n) from `start` with the inverse kinematic matrix m_inv (Eq. 6), calling
// visit(k, pose(k+1)) after every sample. Returns the final pose.
template <typename T, typename Visitor = internal::NoVisit>
Pose2<T> ReplayWithMatrix(const Matrix3<T>& m_inv, const WheelSample* samples, std::size_t n,
                          const Pose2<T>& start, Visitor&& visit = Visitor()) {
  using std::cos;
  using std::sin;
  T x = start.x;
  T y = start.y;
  T theta = start.theta;
  std::size_t k = 0;
  while (k < n) {
    T c = cos(theta);
    T s = sin(theta);
    const std::size_t chunk_end = k + internal::kReanchorInterval < n
                                      ? k + internal::kReanchorInterval : n;
    for (; k < chunk_end; ++k) {
      const WheelSample& sample = samples[k];
      const double* w = sample.rate_rad_s;
      // Robot-frame velocity M^-1 w (Eq. 4), scaled by the interval length.
      const T vx = m_inv(0, 0) * w[0] + m_inv(0, 1) * w[1] + m_inv(0, 2) * w[2];
      const T vy = m_inv(1, 0) * w[0] + m_inv(1, 1) * w[1] + m_inv(1, 2) * w[2];
      const T omega = m_inv(2, 0) * w[0] + m_inv(2, 1) * w[1] + m_inv(2, 2) * w[2];
      const T dx_robot = vx * sample.dt_s;
      const T dy_robot = vy * sample.dt_s;
      const T dtheta = omega * sample.dt_s;
      // R(theta(k-1))^-1 of Eq. 5 rotates the robot-frame step into the world frame.
      x += c * dx_robot - s * dy_robot;
      y += s * dx_robot + c * dy_robot;
      theta += dtheta;
      T cd, sd;
      internal::CosSinOfSmallAngle(dtheta, &cd, &sd);
      const T c_next = c * cd - s * sd;
      s = s * cd + c * sd;
      c = c_next;
      visit(k, Pose2<T>{x, y, theta});
    }
  }
  return Pose2<T>{x, y, theta};
}

// The final pose of a run replayed with the nine parameters p (Eq. 15 order).
template <typename T>
Pose2<T> ReplayFinalPose(const T* p, const WheelSamples& samples, const Pose2<T>& start) {
  return ReplayWithMatrix(InverseKinematicMatrix(p), samples.data(), samples.size(), start);
}

}  // namespace fitcal::omni3
