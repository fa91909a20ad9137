#pragma once
// The two pose errors every fit of every model minimises, written once, templated on the scalar
// (Ceres differentiates them, the CF evaluation and the NLopt back end call them on double).
//
// Final pose, Palacin Eq. 14: the replayed odometry's final pose minus the ground truth's,
// heading difference wrapped to [-pi, pi):
//   r = [ (x_f - x_gt) / sigma_xy,  (y_f - y_gt) / sigma_xy,  wrap(theta_f - theta_gt) / sigma_th ]
// With sigmas of 1 (m and rad) |r| is the paper's per-run CF.
//
// Segment (relative pose error, Sturm et al. 2012 Eq. 3; evo `evo_rpe`; KITTI's segments by
// travelled distance): for a window (i, j) with odometry P_ij = P_i^-1 P_j and ground truth
// Q_ij = Q_i^-1 Q_j,
//   r = [ R(-theta_Qij) (t_Pij - t_Qij) / sigma_xy,  wrap(theta_Pij - theta_Qij) / sigma_th ]
// so |r| per window is the final-pose CF of the window.

#include <cmath>

#include "models/model_interface.h"
#include "odometry/pose2.h"

namespace fitcal {

template <typename T>
void FinalPoseError(const Pose2<T>& odometry, const Pose2d& ground_truth,
                    const ResidualWeights& weights, T* residual) {
  const double inv_position_sigma = 1.0 / weights.position_sigma_m;
  const double inv_heading_sigma = 1.0 / weights.heading_sigma_rad;
  residual[0] = (odometry.x - ground_truth.x) * inv_position_sigma;
  residual[1] = (odometry.y - ground_truth.y) * inv_position_sigma;
  residual[2] = WrapAngle(odometry.theta - ground_truth.theta) * inv_heading_sigma;
}

// a, b: odometry poses at the window's start and end; q: the ground truth's Q_ij.
template <typename T>
void SegmentError(const Pose2<T>& a, const Pose2<T>& b, const Pose2d& q,
                  const ResidualWeights& weights, T* residual) {
  using std::cos;
  using std::sin;
  const double inv_position_sigma = 1.0 / weights.position_sigma_m;
  const double inv_heading_sigma = 1.0 / weights.heading_sigma_rad;
  // P_ij = P_i^-1 P_j
  const T ca = cos(a.theta), sa = sin(a.theta);
  const T dx = b.x - a.x, dy = b.y - a.y;
  const T px = ca * dx + sa * dy;
  const T py = -sa * dx + ca * dy;
  const T ptheta = b.theta - a.theta;
  // E = Q_ij^-1 P_ij, translation in Q_ij's end frame.
  const double cq = std::cos(q.theta), sq = std::sin(q.theta);
  const T ex = px - T(q.x), ey = py - T(q.y);
  residual[0] = (cq * ex + sq * ey) * inv_position_sigma;
  residual[1] = (-sq * ex + cq * ey) * inv_position_sigma;
  residual[2] = WrapAngle(ptheta - T(q.theta)) * inv_heading_sigma;
}

}  // namespace fitcal
