#pragma once
// The test oracle of the omni3 replay: dead reckoning of a three-wheeled omni robot written as
// Palacin et al. 2022 Eq. 4 for one robot,
//   pose(k) = pose(k-1) + dt_k * R(theta(k-1))^-1 * M^-1 * w(k)
// with R^-1 of Eq. 5 and M^-1 of Eq. 6 (models/omni3/omni3_parameters.h). fitcal replays every
// model through the seam (odometry/replay.h, models/omni3/omni3_kinematics.h); the tests and one
// benchmark check that replay against this one. Templated on the scalar (double and ceres::Jet).
//
// Speed: the replay runs in chunks of kChunk samples. A first pass computes every sample's
// robot-frame step M^-1 w dt and the rotation (cos, sin) over its interval; these do not depend on
// each other, so for double the compiler vectorises the pass. The rotation uses a short Taylor
// series, as long as the chunk's largest per-sample angle needs (exact to < 1e-17), and the
// library sin/cos above kSeriesMaxAngle. A second, sequential pass accumulates the world pose and
// advances the heading's unit vector (c, s) by those rotations; (c, s) is recomputed exactly from
// theta every kReanchorInterval samples so rounding cannot accumulate. The result equals a literal
// Eq. 4 to rounding (tests/omni3_replay_test.cc).

#include <cassert>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "models/omni3/omni3_parameters.h"
#include "odometry/encoder_samples.h"
#include "odometry/pose2.h"
#include "odometry/replay.h"

namespace fitcal::omni3 {

namespace internal {

// The chunk, re-anchoring interval and per-chunk rotations (series by the chunk's largest angle)
// are the generic replay's (odometry/replay.h).
using replay_internal::kChunk;
using replay_internal::kReanchorInterval;
using replay_internal::NoVisit;

}  // namespace internal

// Replays samples[begin..begin+n) (three channels: the wheel rates) from `start` with the
// inverse kinematic matrix m_inv (Eq. 6), calling visit(k, pose after samples[k]) after every
// sample. Returns the final pose.
template <typename T, typename Visitor = internal::NoVisit>
Pose2<T> ReplayWithMatrix(const Matrix3<T>& m_inv, const EncoderSamples& samples, std::size_t begin,
                          std::size_t n, const Pose2<T>& start, Visitor&& visit = Visitor()) {
  using internal::kChunk;
  using std::abs;
  using std::cos;
  using std::sin;
  // Rows of three channels, [dt, w_0, w_1, w_2]: a compile-time stride keeps the loads as the
  // compiler vectorises them.
  constexpr std::size_t kStride = 4;
  assert(samples.stride() == static_cast<int>(kStride));
  assert(begin + n <= samples.size());
  const double* rows = samples.data() + begin * kStride;
  // Locals, so the compiler knows the matrix does not alias the buffers.
  const T m00 = m_inv(0, 0), m01 = m_inv(0, 1), m02 = m_inv(0, 2);
  const T m10 = m_inv(1, 0), m11 = m_inv(1, 1), m12 = m_inv(1, 2);
  const T m20 = m_inv(2, 0), m21 = m_inv(2, 1), m22 = m_inv(2, 2);
  T step_x[kChunk], step_y[kChunk], step_theta[kChunk], rot_c[kChunk], rot_s[kChunk];

  T x = start.x;
  T y = start.y;
  T theta = start.theta;
  T c = cos(theta);
  T s = sin(theta);
  for (std::size_t k0 = 0; k0 < n; k0 += kChunk) {
    const std::size_t m = n - k0 < kChunk ? n - k0 : kChunk;
    const double* chunk = rows + k0 * kStride;
    // Pass 1: robot-frame step M^-1 w dt of every sample (Eq. 4) and its rotation.
    for (std::size_t j = 0; j < m; ++j) {
      const double* w = chunk + j * kStride + 1;
      const double dt = chunk[j * kStride];
      step_x[j] = (m00 * w[0] + m01 * w[1] + m02 * w[2]) * dt;
      step_y[j] = (m10 * w[0] + m11 * w[1] + m12 * w[2]) * dt;
      step_theta[j] = (m20 * w[0] + m21 * w[1] + m22 * w[2]) * dt;
    }
    replay_internal::ChunkRotations(step_theta, m, rot_c, rot_s);
    // Pass 2: R(theta(k-1))^-1 of Eq. 5 rotates each step into the world frame. On double the
    // loop is latency-bound, so it takes two samples per iteration: (c, s) advances by the
    // product of their rotations, which does not depend on (c, s), halving the loop-carried chain
    // (the pose between them uses (c1, s1)). Jets are throughput-bound: there the extra products
    // would cost more than they save, so they go one sample at a time.
    std::size_t j = 0;
    constexpr bool kPairSamples = std::is_same_v<T, double>;
    for (; kPairSamples && j + 1 < m; j += 2) {
      x += c * step_x[j] - s * step_y[j];
      y += s * step_x[j] + c * step_y[j];
      theta += step_theta[j];
      visit(begin + k0 + j, Pose2<T>{x, y, theta});
      const T c1 = c * rot_c[j] - s * rot_s[j];
      const T s1 = s * rot_c[j] + c * rot_s[j];
      x += c1 * step_x[j + 1] - s1 * step_y[j + 1];
      y += s1 * step_x[j + 1] + c1 * step_y[j + 1];
      theta += step_theta[j + 1];
      visit(begin + k0 + j + 1, Pose2<T>{x, y, theta});
      const T rc2 = rot_c[j] * rot_c[j + 1] - rot_s[j] * rot_s[j + 1];
      const T rs2 = rot_s[j] * rot_c[j + 1] + rot_c[j] * rot_s[j + 1];
      const T c2 = c * rc2 - s * rs2;
      s = s * rc2 + c * rs2;
      c = c2;
    }
    for (; j < m; ++j) {
      x += c * step_x[j] - s * step_y[j];
      y += s * step_x[j] + c * step_y[j];
      theta += step_theta[j];
      visit(begin + k0 + j, Pose2<T>{x, y, theta});
      const T c_next = c * rot_c[j] - s * rot_s[j];
      s = s * rot_c[j] + c * rot_s[j];
      c = c_next;
    }
    if ((k0 + m) % internal::kReanchorInterval == 0) {
      c = cos(theta);
      s = sin(theta);
    }
  }
  return Pose2<T>{x, y, theta};
}

// The final pose of a run replayed with the nine parameters p (Eq. 15 order).
template <typename T>
Pose2<T> ReplayFinalPose(const T* p, const EncoderSamples& samples, const Pose2<T>& start) {
  return ReplayWithMatrix(InverseKinematicMatrix(p), samples, 0, samples.size(), start);
}

}  // namespace fitcal::omni3
