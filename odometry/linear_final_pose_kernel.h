#pragma once
// The final pose of the replay (odometry/replay.h, Palacin Eq. 4) for kinematics whose body step
// is linear in the channel values, (dx, dy, dtheta)_k = dt_k M(p) w_k with M 3 x n
// (FinalPoseJacobianKind::kLinearInChannels in models/model_interface.h: omni3's M^-1 of Eq. 6,
// the omni/mecanum robots), on double, from per-run data prepared once: the evaluation a global
// search (NLopt) repeats tens of thousands of times. Equal to the replay to rounding
// (tests/linear_final_pose_kernel_test.cc); the replay stays for everything else.
//
// Why it is faster: with m_x, m_y, m_theta the rows of M and u(k) = w(k) dt(k), the heading
// before sample k is linear in m_theta over the cumulative channel travel, which the parameters
// do not change,
//   theta(k-1) = theta_0 + m_theta . W(k),   W(k) = sum_{j<k} u(j),
// and the position is linear in m_x and m_y,
//   x_f = x_0 + m_x . C - m_y . S,   y_f = y_0 + m_x . S + m_y . C,
//   C = sum_k cos(theta(k-1)) u(k),   S = sum_k sin(theta(k-1)) u(k).
// No sample waits for the previous one, so every sum vectorises. Samples are taken in blocks of
// kBlock around an anchor b (the block's middle): theta(k-1) = theta_b + delta_k with
// delta_k = m_theta . (W(k) - W(b)), whose cos/sin come from a Taylor series of the degree the
// block's largest |delta| needs (truncation < 1e-18), and from the library above 1 rad.

#include <array>
#include <cstddef>
#include <vector>

#include "odometry/encoder_samples.h"
#include "odometry/pose2.h"

namespace fitcal {

// Owns the run's channel steps u(k) and their offsets W(k) - W(b) from their block's anchor, by
// channel (structure of arrays, so the block sums load whole vectors).
class LinearFinalPoseKernel {
 public:
  static constexpr std::size_t kBlock = 64;

  // From samples[begin..begin+n), every channel.
  LinearFinalPoseKernel(const EncoderSamples& samples, std::size_t begin, std::size_t n);
  explicit LinearFinalPoseKernel(const EncoderSamples& samples)
      : LinearFinalPoseKernel(samples, 0, samples.size()) {}

  // The final pose of Eq. 4 from `start` with the step matrix m: 3 x num_channels(), row-major
  // (rows x, y, theta of the body step per unit channel value and second).
  Pose2d FinalPose(const double* m, const Pose2d& start) const;

  std::size_t size() const { return size_; }
  int num_channels() const { return static_cast<int>(step_.size()); }

 private:
  std::size_t size_ = 0;
  std::vector<std::vector<double>> step_;    // u(k), per channel
  std::vector<std::vector<double>> offset_;  // W(k) - W(anchor of k's block), per channel
  std::vector<std::vector<double>> anchor_;  // W(b) of every block, per channel
  std::vector<double> total_;                // W(n): the heading change is m_theta . W(n)
};

}  // namespace fitcal
