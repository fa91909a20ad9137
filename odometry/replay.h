#pragma once
// Dead reckoning for any kinematic model: every encoder interval k moves the robot by a
// body-frame step (dx_k, dy_k, dtheta_k) that the model computes from the interval's channel
// values, and the step is rotated into the world frame at the heading before it (Palacin Eq. 4
// and 5 for the three-wheel case, where the step is dt_k M^-1 w_k):
//
//   x_k = x_{k-1} + cos(theta_{k-1}) dx_k - sin(theta_{k-1}) dy_k
//   y_k = y_{k-1} + sin(theta_{k-1}) dx_k + cos(theta_{k-1}) dy_k
//   theta_k = theta_{k-1} + dtheta_k
//
// Templated on the scalar: Ceres differentiates through it with ceres::Jet.
//
// Speed: samples are replayed in chunks of kChunk. A first pass computes every sample's step and
// the rotation (cos, sin) of its dtheta; these do not depend on each other, so for double the
// compiler vectorises the pass. The rotation uses a short Taylor series, as long as the chunk's
// largest per-sample angle needs (exact to < 1e-17), and the library sin/cos above
// kSeriesMaxAngle. A second, sequential pass accumulates the world pose and advances the
// heading's unit vector (c, s) by those rotations; (c, s) is recomputed exactly from theta every
// kReanchorInterval samples so rounding cannot accumulate. The result equals a literal Eq. 4 to
// rounding (tests/model_harness_test.cc; for Palacin's robot, against the test oracle of tests/).

#include <cmath>
#include <cstddef>
#include <type_traits>

#include "odometry/encoder_samples.h"
#include "odometry/pose2.h"

// The body step runs once per sample inside the replay's hot loop: on ceres::Jet its arithmetic
// must be inlined there, or every Jet operation becomes a call (5x slower fits with GCC 12).
#define FITCAL_ALWAYS_INLINE inline __attribute__((always_inline))

namespace fitcal {

namespace replay_internal {

inline constexpr std::size_t kChunk = 64;
inline constexpr std::size_t kReanchorInterval = 256;  // a multiple of kChunk
// Per-sample rotations below kTinySeriesMaxAngle use the degree-4/5 series (truncation error
// < a^6/6! < 2.2e-17), below kShortSeriesMaxAngle the degree-6/7 series (< a^8/8! < 7e-19),
// below kSeriesMaxAngle the degree-10/11 series (< a^12/12! < 9e-18); larger ones (never at sane
// sample rates) the library functions.
inline constexpr double kTinySeriesMaxAngle = 0.005;
inline constexpr double kShortSeriesMaxAngle = 0.02;
inline constexpr double kSeriesMaxAngle = 0.2;

inline void CosSinTinySeries(double a, double* c, double* s) {
  const double a2 = a * a;
  *c = 1.0 + a2 * (-1.0 / 2 + a2 * (1.0 / 24));
  *s = a * (1.0 + a2 * (-1.0 / 6 + a2 * (1.0 / 120)));
}

inline void CosSinShortSeries(double a, double* c, double* s) {
  const double a2 = a * a;
  *c = 1.0 + a2 * (-1.0 / 2 + a2 * (1.0 / 24 + a2 * (-1.0 / 720)));
  *s = a * (1.0 + a2 * (-1.0 / 6 + a2 * (1.0 / 120 + a2 * (-1.0 / 5040))));
}

inline void CosSinLongSeries(double a, double* c, double* s) {
  const double a2 = a * a;
  *c =
      1.0 + a2 * (-1.0 / 2 +
                  a2 * (1.0 / 24 + a2 * (-1.0 / 720 + a2 * (1.0 / 40320 + a2 * (-1.0 / 3628800)))));
  *s = a * (1.0 + a2 * (-1.0 / 6 +
                        a2 * (1.0 / 120 +
                              a2 * (-1.0 / 5040 + a2 * (1.0 / 362880 + a2 * (-1.0 / 39916800))))));
}

// For a ceres::Jet the series runs on the real part only and the derivatives follow from the
// chain rule, d cos = -sin da, d sin = cos da: two vector scalings instead of a polynomial in
// Jets (half of the autodiff replay's cost otherwise).
template <typename JetT, typename Series>
FITCAL_ALWAYS_INLINE void CosSinOfJet(const JetT& a, JetT* c, JetT* s, Series series) {
  double cv, sv;
  series(a.a, &cv, &sv);
  *c = JetT(cv, -sv * a.v);
  *s = JetT(sv, cv * a.v);
}

template <typename T, typename Series>
FITCAL_ALWAYS_INLINE void CosSin(const T& a, T* c, T* s, Series series) {
  if constexpr (std::is_same_v<T, double>) {
    series(a, c, s);
  } else {
    CosSinOfJet(a, c, s, series);
  }
}

// The rotation of every step of a chunk, with the cheapest series its largest angle allows.
template <typename T>
FITCAL_ALWAYS_INLINE void ChunkRotations(const T* step_theta, std::size_t m, T* rot_c, T* rot_s) {
  using std::cos;
  using std::sin;
  double max_angle = 0.0;
  for (std::size_t j = 0; j < m; ++j) {
    const double a = std::abs(ScalarPart(step_theta[j]));
    max_angle = a > max_angle ? a : max_angle;
  }
  if (max_angle < kTinySeriesMaxAngle) {
    for (std::size_t j = 0; j < m; ++j) {
      CosSin(step_theta[j], &rot_c[j], &rot_s[j], CosSinTinySeries);
    }
  } else if (max_angle < kShortSeriesMaxAngle) {
    for (std::size_t j = 0; j < m; ++j) {
      CosSin(step_theta[j], &rot_c[j], &rot_s[j], CosSinShortSeries);
    }
  } else if (max_angle < kSeriesMaxAngle) {
    for (std::size_t j = 0; j < m; ++j) {
      CosSin(step_theta[j], &rot_c[j], &rot_s[j], CosSinLongSeries);
    }
  } else {
    for (std::size_t j = 0; j < m; ++j) {
      rot_c[j] = cos(step_theta[j]);
      rot_s[j] = sin(step_theta[j]);
    }
  }
}

struct NoVisit {
  template <typename T>
  void operator()(std::size_t, const Pose2<T>&) const {}
};

}  // namespace replay_internal

// A visitor that also wants every step as the replay applies it derives from StepVisitor and
// provides Steps(k0, m, c, s, dx, dy, dtheta): samples k0 .. k0 + m - 1 of a chunk, their
// body-frame steps and the unit vectors (c, s) = (cos, sin) of the heading before each, exactly
// the values the replay rotated the steps with. It is called once per chunk, after the chunk's
// poses, so the visitor can sum over the chunk with its accumulators in registers (the
// analytic final-pose Jacobian, models/final_pose_jacobian.h).
struct StepVisitor {
  template <typename T>
  void operator()(std::size_t, const Pose2<T>&) const {}
};

// Replays samples [begin, end) from `start`. body_step(values, dt, &dx, &dy, &dtheta) gives the
// body-frame step of one interval from its channel values (model-specific). Calls
// visit(k, pose after sample k) for every sample. Returns the final pose.
template <typename T, typename BodyStep, typename Visitor = replay_internal::NoVisit>
Pose2<T> ReplaySteps(const BodyStep& body_step, const EncoderSamples& samples, std::size_t begin,
                     std::size_t end, const Pose2<T>& start, Visitor&& visit = Visitor()) {
  using replay_internal::kChunk;
  using std::cos;
  using std::sin;
  T step_x[kChunk], step_y[kChunk], step_theta[kChunk], rot_c[kChunk], rot_s[kChunk];
  constexpr bool kWantsSteps = std::is_base_of_v<StepVisitor, std::decay_t<Visitor>>;
  // The heading vector before each step of the chunk, for a StepVisitor.
  T heading_c[kWantsSteps ? kChunk : 1], heading_s[kWantsSteps ? kChunk : 1];
  const std::size_t stride = static_cast<std::size_t>(samples.stride());
  const double* rows = samples.data();

  T x = start.x;
  T y = start.y;
  T theta = start.theta;
  T c = cos(theta);
  T s = sin(theta);
  for (std::size_t k0 = begin; k0 < end; k0 += kChunk) {
    const std::size_t m = end - k0 < kChunk ? end - k0 : kChunk;
    // Pass 1: the body-frame step of every sample and its rotation.
    for (std::size_t j = 0; j < m; ++j) {
      const double* row = rows + (k0 + j) * stride;
      body_step(row + 1, row[0], &step_x[j], &step_y[j], &step_theta[j]);
    }
    replay_internal::ChunkRotations(step_theta, m, rot_c, rot_s);
    // Pass 2: R(theta(k-1))^-1 (Palacin Eq. 5) rotates each step into the world frame. On double
    // the loop is latency-bound, so it takes two samples per iteration: (c, s) advances by the
    // product of their rotations, which does not depend on (c, s), halving the loop-carried chain
    // (the pose between them uses (c1, s1)). Jets are throughput-bound: there the extra products
    // would cost more than they save, so they go one sample at a time.
    std::size_t j = 0;
    constexpr bool kPairSamples = std::is_same_v<T, double>;
    for (; kPairSamples && j + 1 < m; j += 2) {
      if constexpr (kWantsSteps) heading_c[j] = c, heading_s[j] = s;
      x += c * step_x[j] - s * step_y[j];
      y += s * step_x[j] + c * step_y[j];
      theta += step_theta[j];
      visit(k0 + j, Pose2<T>{x, y, theta});
      const T c1 = c * rot_c[j] - s * rot_s[j];
      const T s1 = s * rot_c[j] + c * rot_s[j];
      if constexpr (kWantsSteps) heading_c[j + 1] = c1, heading_s[j + 1] = s1;
      x += c1 * step_x[j + 1] - s1 * step_y[j + 1];
      y += s1 * step_x[j + 1] + c1 * step_y[j + 1];
      theta += step_theta[j + 1];
      visit(k0 + j + 1, Pose2<T>{x, y, theta});
      const T rc2 = rot_c[j] * rot_c[j + 1] - rot_s[j] * rot_s[j + 1];
      const T rs2 = rot_s[j] * rot_c[j + 1] + rot_c[j] * rot_s[j + 1];
      const T c2 = c * rc2 - s * rs2;
      s = s * rc2 + c * rs2;
      c = c2;
    }
    for (; j < m; ++j) {
      if constexpr (kWantsSteps) heading_c[j] = c, heading_s[j] = s;
      x += c * step_x[j] - s * step_y[j];
      y += s * step_x[j] + c * step_y[j];
      theta += step_theta[j];
      visit(k0 + j, Pose2<T>{x, y, theta});
      const T c_next = c * rot_c[j] - s * rot_s[j];
      s = s * rot_c[j] + c * rot_s[j];
      c = c_next;
    }
    if constexpr (kWantsSteps) visit.Steps(k0, m, heading_c, heading_s, step_x, step_y, step_theta);
    if ((k0 + m - begin) % replay_internal::kReanchorInterval == 0) {
      c = cos(theta);
      s = sin(theta);
    }
  }
  return Pose2<T>{x, y, theta};
}

}  // namespace fitcal
