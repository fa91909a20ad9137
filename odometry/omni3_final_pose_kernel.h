#pragma once
// The final pose of Palacin Eq. 4 on double, from per-run data prepared once: the evaluation a
// global search (NLopt) repeats tens of thousands of times. Equal to ReplayWithMatrix to rounding
// (tests/omni3_final_pose_kernel_test.cc); the Ceres fit keeps ReplayWithMatrix for its Jets.
//
// Why it is faster: with m1, m2, m3 the rows of M^-1 (Eq. 6) and u(k) = w(k) dt(k), the heading
// before sample k is linear in m3 over the cumulative wheel angles, which the parameters do not
// change,
//   theta(k-1) = theta_0 + m3 . W(k),   W(k) = sum_{j<k} u(j),
// and the position is linear in m1 and m2,
//   x_f = x_0 + m1 . C - m2 . S,   y_f = y_0 + m1 . S + m2 . C,
//   C = sum_k cos(theta(k-1)) u(k),   S = sum_k sin(theta(k-1)) u(k).
// No sample waits for the previous one, so every sum vectorises. Samples are taken in blocks of
// kBlock around an anchor b (the block's middle): theta(k-1) = theta_b + delta_k with
// delta_k = m3 . (W(k) - W(b)), whose cos/sin come from a Taylor series of the degree the block's
// largest |delta| needs (truncation < 1e-18), and from the library above 1 rad.

#include <array>
#include <cstddef>
#include <vector>

#include "odometry/encoder_samples.h"
#include "odometry/omni3_model.h"
#include "odometry/pose2.h"

namespace fitcal::omni3 {

// Owns the run's wheel steps u(k) and their offsets W(k) - W(b) from their block's anchor, by
// component (structure of arrays, so the block sums load whole vectors).
class FinalPoseKernel {
 public:
  static constexpr std::size_t kBlock = 64;

  // From samples[begin..begin+n) (three channels: the wheel rates).
  FinalPoseKernel(const EncoderSamples& samples, std::size_t begin, std::size_t n);
  explicit FinalPoseKernel(const EncoderSamples& samples)
      : FinalPoseKernel(samples, 0, samples.size()) {}

  // The final pose of Eq. 4 from `start` with the inverse kinematic matrix m_inv (Eq. 6).
  Pose2d FinalPose(const Matrix3<double>& m_inv, const Pose2d& start) const;

  std::size_t size() const { return step_[0].size(); }

 private:
  std::array<std::vector<double>, 3> step_;    // u(k), per wheel
  std::array<std::vector<double>, 3> offset_;  // W(k) - W(anchor of k's block), per wheel
  std::vector<std::array<double, 3>> anchor_;  // W(b) of every block
  std::array<double, 3> total_{};              // W(n): the heading change is m3 . W(n)
};

}  // namespace fitcal::omni3
