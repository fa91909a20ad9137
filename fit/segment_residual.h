#pragma once
// The segment (relative pose error) residual of one run: the trajectory is cut into windows of a
// set ground-truth path length, and every window compares the motion the odometry replays over it
// with the motion the ground truth measured, both expressed in the window's start frame. This is
// the relative pose error (RPE) of trajectory-evaluation tools (Sturm et al. 2012, TUM RGB-D
// benchmark, Eq. 3: E_i = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j); evo `evo_rpe --delta L --delta_unit m`;
// Geiger et al. 2012 KITTI odometry metric, segments by travelled distance). For window (i, j):
//
//   P_ij = P_i^-1 P_j  (odometry, replayed with the parameters p; Palacin Eq. 4 from identity)
//   Q_ij = Q_i^-1 Q_j  (ground truth at the same instants)
//   r    = [ R(-theta_Qij) (t_Pij - t_Qij) / sigma_xy,  wrap(theta_Pij - theta_Qij) / sigma_theta ]
//
// so |r| per window is the final-pose CF (Eq. 14) of the window. Unlike the final-pose residual it
// uses the intermediate ground truth, so it sees errors that cancel by the end of a closed path.
//
// One functor per run (the replay is shared by all its windows), templated like
// final_pose_residual.h: Ceres differentiates it, the evaluation code calls it on double.

#include <ceres/autodiff_cost_function.h>

#include <algorithm>
#include <cstddef>
#include <vector>

#include "fit/final_pose_residual.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"
#include "odometry/omni3_replay.h"

namespace fitcal {

// The segments of one run, with the run they refer to (which must outlive the functor).
struct SegmentedRun {
  const AlignedRun* run = nullptr;
  std::vector<Segment> segments;
};

class Omni3SegmentResidual {
 public:
  Omni3SegmentResidual(const SegmentedRun& run, const ResidualWeights& weights)
      : run_(run),
        inv_position_sigma_(1.0 / weights.position_sigma_m),
        inv_heading_sigma_(1.0 / weights.heading_sigma_rad) {
    // Poses are needed after these sample counts (window starts and ends), in order.
    for (const Segment& s : run_.segments) {
      marks_.push_back(s.begin);
      marks_.push_back(s.end);
    }
    std::sort(marks_.begin(), marks_.end());
    marks_.erase(std::unique(marks_.begin(), marks_.end()), marks_.end());
  }

  int NumResiduals() const { return 3 * static_cast<int>(run_.segments.size()); }

  template <typename T>
  bool operator()(const T* p, T* residual) const {
    ResidualsWithMatrix(omni3::InverseKinematicMatrix(p), residual);
    return true;
  }

  // The residuals replayed with any inverse kinematic matrix (e.g. Eq. 6 times a wheel mapping).
  template <typename T>
  void ResidualsWithMatrix(const omni3::Matrix3<T>& m_inv, T* residual) const {
    using std::cos;
    using std::sin;
    const AlignedRun& run = *run_.run;
    // Replay once from the identity, keeping the pose after every marked sample count.
    std::vector<Pose2<T>> at_mark(marks_.size());
    Pose2<T> pose{T(0.0), T(0.0), T(0.0)};
    std::size_t done = 0;
    for (std::size_t m = 0; m < marks_.size(); ++m) {
      if (marks_[m] > done) {
        pose = omni3::ReplayWithMatrix(m_inv, run.samples, done, marks_[m] - done, pose);
        done = marks_[m];
      }
      at_mark[m] = pose;
    }
    for (std::size_t k = 0; k < run_.segments.size(); ++k) {
      const Segment& s = run_.segments[k];
      const Pose2<T>& a = at_mark[IndexOf(s.begin)];
      const Pose2<T>& b = at_mark[IndexOf(s.end)];
      // P_ij = P_i^-1 P_j
      const T ca = cos(a.theta), sa = sin(a.theta);
      const T dx = b.x - a.x, dy = b.y - a.y;
      const T px = ca * dx + sa * dy;
      const T py = -sa * dx + ca * dy;
      const T ptheta = b.theta - a.theta;
      // E = Q_ij^-1 P_ij, translation in Q_ij's end frame.
      const Pose2d& q = s.ground_truth_start_T_end;
      const double cq = std::cos(q.theta), sq = std::sin(q.theta);
      const T ex = px - T(q.x), ey = py - T(q.y);
      residual[3 * k + 0] = (cq * ex + sq * ey) * inv_position_sigma_;
      residual[3 * k + 1] = (-sq * ex + cq * ey) * inv_position_sigma_;
      residual[3 * k + 2] = WrapAngle(ptheta - T(q.theta)) * inv_heading_sigma_;
    }
  }

  static ceres::CostFunction* Create(const SegmentedRun& run, const ResidualWeights& weights) {
    auto* functor = new Omni3SegmentResidual(run, weights);
    return new ceres::AutoDiffCostFunction<Omni3SegmentResidual, ceres::DYNAMIC,
                                           omni3::kNumParameters>(functor, functor->NumResiduals());
  }

 private:
  std::size_t IndexOf(std::size_t mark) const {
    return static_cast<std::size_t>(std::lower_bound(marks_.begin(), marks_.end(), mark) -
                                    marks_.begin());
  }

  const SegmentedRun& run_;
  double inv_position_sigma_;
  double inv_heading_sigma_;
  std::vector<std::size_t> marks_;
};

}  // namespace fitcal
