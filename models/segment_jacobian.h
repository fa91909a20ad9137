#pragma once
// The segment residuals of one run (models/pose_errors.h SegmentError; the track residual's
// odometry poses from the run's start, fit/track_residual.h, are segments [0, k] with an
// identity ground truth) with an analytic Jacobian, for the kinematics whose final-pose cost has
// one (models/final_pose_jacobian.h). Same residuals as the autodiff ModelSegmentResidual
// (kinematic_model.h), same Jacobian to rounding (tests/final_pose_jacobian_test.cc,
// SegmentJacobian.*); cheaper, because autodiff carries a Jet of all P parameters through every
// sample of the replay (the largest share of every track fit).
//
// The run is replayed once from the identity, in double, stopping at every window start and end
// (a "mark") as the residual-only evaluation does, so the poses are its own bit for bit. The
// derivatives of the pose P_m at mark m are those of the final-pose header taken as prefix sums
// (forward mode by hand): with c_k, s_k the heading's unit vector before step k, G_k = dS_k/dp
// the body step's derivative and T_k = sum_{j<k} G_j,theta,
//   dx_m/dp = sum_{k<m} (c_k G_kx - s_k G_ky - Dy_k T_k),
//   dy_m/dp = sum_{k<m} (s_k G_kx + c_k G_ky + Dx_k T_k),   dtheta_m/dp = T_m,
// the sums read at each mark (kPerSampleStep: PerSampleSums; kLinearInChannels: the channel sums
// and dM/dp, PoseDerivatives). The segment error of two marks is then differentiated with Jets of
// P seeded by those rows: per window, not per sample.

#include <ceres/cost_function.h>
#include <ceres/jet.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

#include "models/final_pose_jacobian.h"
#include "models/model_interface.h"
#include "models/pose_errors.h"
#include "models/replay_kinematics.h"
#include "odometry/aligned_run.h"

namespace fitcal {

// The sorted, distinct window starts and ends of `segments`: where a segment replay stops.
inline std::vector<std::size_t> SegmentMarks(const std::vector<Segment>& segments) {
  std::vector<std::size_t> marks;
  for (const Segment& s : segments) {
    marks.push_back(s.begin);
    marks.push_back(s.end);
  }
  std::sort(marks.begin(), marks.end());
  marks.erase(std::unique(marks.begin(), marks.end()), marks.end());
  return marks;
}

// Where `mark` (a window start or end) stands in SegmentMarks' list.
inline std::size_t MarkIndex(const std::vector<std::size_t>& marks, std::size_t mark) {
  return static_cast<std::size_t>(std::lower_bound(marks.begin(), marks.end(), mark) -
                                  marks.begin());
}

template <class K>
class SegmentJacobianCost final : public ceres::CostFunction {
 public:
  static constexpr int P = K::kNumParameters;
  static constexpr FinalPoseJacobianKind kKind = FinalPoseJacobianKindOf<K>::value;
  static_assert(kKind != FinalPoseJacobianKind::kAutodiff, "K has no analytic Jacobian");
  using JetP = ceres::Jet<double, P>;
  using Derivatives = std::array<final_pose_jacobian_internal::Row<P>, 3>;  // d(x, y, theta)/dp

  // `segments` must outlive the cost (as ModelSegmentResidual's).
  SegmentJacobianCost(const AlignedRun& run, const std::vector<Segment>& segments,
                      const ResidualWeights& weights, const K& kinematics)
      : run_(run),
        segments_(segments),
        weights_(weights),
        kinematics_(kinematics),
        marks_(SegmentMarks(segments)) {
    set_num_residuals(3 * static_cast<int>(segments.size()));
    mutable_parameter_block_sizes()->push_back(P);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* p = parameters[0];
    const bool want_jacobian = jacobians != nullptr && jacobians[0] != nullptr;
    std::vector<Pose2d> at_mark(marks_.size());
    std::vector<Derivatives> d_at_mark(want_jacobian ? marks_.size() : 0);
    if (want_jacobian) {
      ReplayWithDerivatives(p, &at_mark, &d_at_mark);
    } else {
      ReplayTo(p, &at_mark, [](std::size_t) {});
    }
    for (std::size_t k = 0; k < segments_.size(); ++k) {
      const Segment& s = segments_[k];
      const std::size_t a = MarkIndex(marks_, s.begin), b = MarkIndex(marks_, s.end);
      SegmentError(at_mark[a], at_mark[b], s.ground_truth_start_T_end, weights_, residuals + 3 * k);
      if (!want_jacobian) continue;
      JetP r[3];
      SegmentError(WithDerivatives(at_mark[a], d_at_mark[a]),
                   WithDerivatives(at_mark[b], d_at_mark[b]), s.ground_truth_start_T_end,
                   weights_, r);
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < P; ++j) jacobians[0][(3 * k + i) * P + j] = r[i].v[j];
      }
    }
    return true;
  }

 private:
  // The replay from the identity to every mark (as ModelSegmentResidual on double), with
  // `visitor` over the steps and `at_mark(m)` called once the pose at mark m is known.
  template <typename AtMark, typename Visitor = replay_internal::NoVisit>
  void ReplayTo(const double* p, std::vector<Pose2d>* poses, AtMark&& at_mark,
                Visitor&& visitor = Visitor()) const {
    Pose2d pose{0.0, 0.0, 0.0};
    std::size_t done = 0;
    for (std::size_t m = 0; m < marks_.size(); ++m) {
      if (marks_[m] > done) {
        pose = ReplayKinematics(kinematics_, p, run_.samples, done, marks_[m], pose, visitor);
        done = marks_[m];
      }
      (*poses)[m] = pose;
      at_mark(m);
    }
  }
  void ReplayWithDerivatives(const double* p, std::vector<Pose2d>* poses,
                             std::vector<Derivatives>* d) const {
    std::array<JetP, P> p_jet;
    for (int j = 0; j < P; ++j) p_jet[j] = JetP(p[j], j);
    const auto prepared_jet = kinematics_.Prepare(p_jet.data());
    if constexpr (kKind == FinalPoseJacobianKind::kPerSampleStep) {
      final_pose_jacobian_internal::PerSampleSums<K, decltype(prepared_jet)> sums(
          kinematics_, p, prepared_jet, run_.samples);
      ReplayTo(
          p, poses, [&](std::size_t m) { (*d)[m] = {sums.d_x, sums.d_y, sums.d_theta}; }, sums);
    } else {
      constexpr int N = K::kNumChannels;
      using final_pose_jacobian_internal::PoseDerivatives;
      const auto m_jet = final_pose_jacobian_internal::StepMatrixJets<N>(kinematics_, prepared_jet);
      final_pose_jacobian_internal::ChannelSums<N> sums(run_.samples);
      ReplayTo(
          p, poses, [&](std::size_t m) { (*d)[m] = PoseDerivatives<P>(m_jet, sums); }, sums);
    }
  }

  static Pose2<JetP> WithDerivatives(const Pose2d& pose, const Derivatives& d) {
    Pose2<JetP> out{JetP(pose.x), JetP(pose.y), JetP(pose.theta)};
    for (int j = 0; j < P; ++j) {
      out.x.v[j] = d[0][j];
      out.y.v[j] = d[1][j];
      out.theta.v[j] = d[2][j];
    }
    return out;
  }

  const AlignedRun& run_;
  const std::vector<Segment>& segments_;
  ResidualWeights weights_;
  K kinematics_;
  std::vector<std::size_t> marks_;
};

}  // namespace fitcal
