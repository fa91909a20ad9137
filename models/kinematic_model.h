#pragma once
// From a model's kinematics to the whole seam (model_interface.h), written once for every model.
//
// A model's kinematics K is a struct of static functions, templated on the scalar so that Ceres
// differentiates through them:
//
//   struct K {
//     static constexpr int kNumParameters = ...;  // length of the parameter vector
//     // Whatever depends on the parameters only (e.g. Palacin's M^-1), computed once per replay.
//     template <typename T> static Prepared<T> Prepare(const T* p);
//     // The body-frame step (dx, dy, dtheta) of one encoder interval of length dt from its
//     // channel values (wheel rates in rad/s, angles in rad; C = double, or T under effects).
//     template <typename T, typename C>
//     FITCAL_ALWAYS_INLINE static void BodyStep(const Prepared<T>& k, const C* values, double dt,
//                          T* dx, T* dy, T* dtheta);
//     // Inverse kinematics: channel values that drive the twist, false if the model cannot.
//     static bool ChannelsForTwist(const double* p, const Twist& twist, double* values);
//   };
//
// A K whose kinematics depend on fixed geometry that is not fitted (e.g. the omni model's drive
// and roller angles, models/omni/omni_kinematics.h) holds it as data members and makes these
// functions const members instead; it is passed as an instance below. A K of static functions is
// default-constructed, so both kinds go through the same code.
//
// KinematicModel<K> turns it into a RobotModelInterface: the generic replay (odometry/replay.h),
// the final-pose and segment residuals (models/pose_errors.h) as autodiff cost functions. A model's
// own class derives from it and adds its YAML and anything model-specific.

#include <ceres/autodiff_cost_function.h>

#include <algorithm>
#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "models/final_pose_jacobian.h"
#include "models/model_interface.h"
#include "models/pose_errors.h"
#include "models/replay_kinematics.h"
#include "models/segment_jacobian.h"
#include "odometry/aligned_run.h"
#include "odometry/replay.h"

namespace fitcal {

// Palacin Eq. 14 residual of one run for the kinematics K.
template <class K>
class ModelFinalPoseResidual {
 public:
  ModelFinalPoseResidual(const AlignedRun& run, const ResidualWeights& weights,
                         const K& kinematics = K())
      : run_(run), weights_(weights), kinematics_(kinematics) {}

  template <typename T>
  bool operator()(const T* p, T* residual) const {
    const Pose2<T> start{T(run_.start.x), T(run_.start.y), T(run_.start.theta)};
    const Pose2<T> final_pose =
        ReplayKinematics(kinematics_, p, run_.samples, 0, run_.samples.size(), start);
    FinalPoseError(final_pose, run_.final_ground_truth, weights_, residual);
    return true;
  }

  static ceres::CostFunction* Create(const AlignedRun& run, const ResidualWeights& weights,
                                     const K& kinematics = K()) {
    return new ceres::AutoDiffCostFunction<ModelFinalPoseResidual, 3, K::kNumParameters>(
        new ModelFinalPoseResidual(run, weights, kinematics));
  }

 private:
  const AlignedRun& run_;
  ResidualWeights weights_;
  K kinematics_;
};

// Segment residuals (models/pose_errors.h) of one run for the kinematics K: the run is replayed
// once from the identity, keeping the pose at every window start and end. Autodiff through the
// whole replay: SegmentCost's for kinematics without an analytic Jacobian, and the reference the
// analytic SegmentJacobianCost (segment_jacobian.h) is tested against.
template <class K>
class ModelSegmentResidual {
 public:
  ModelSegmentResidual(const AlignedRun& run, const std::vector<Segment>& segments,
                       const ResidualWeights& weights, const K& kinematics = K())
      : run_(run),
        segments_(segments),
        weights_(weights),
        kinematics_(kinematics),
        marks_(SegmentMarks(segments)) {}

  int NumResiduals() const { return 3 * static_cast<int>(segments_.size()); }

  template <typename T>
  bool operator()(const T* p, T* residual) const {
    std::vector<Pose2<T>> at_mark(marks_.size());
    Pose2<T> pose{T(0.0), T(0.0), T(0.0)};
    std::size_t done = 0;
    for (std::size_t m = 0; m < marks_.size(); ++m) {
      if (marks_[m] > done) {
        pose = ReplayKinematics(kinematics_, p, run_.samples, done, marks_[m], pose);
        done = marks_[m];
      }
      at_mark[m] = pose;
    }
    for (std::size_t k = 0; k < segments_.size(); ++k) {
      const Segment& s = segments_[k];
      SegmentError(at_mark[MarkIndex(marks_, s.begin)], at_mark[MarkIndex(marks_, s.end)],
                   s.ground_truth_start_T_end, weights_, residual + 3 * k);
    }
    return true;
  }

  static ceres::CostFunction* Create(const AlignedRun& run, const std::vector<Segment>& segments,
                                     const ResidualWeights& weights, const K& kinematics = K()) {
    auto* functor = new ModelSegmentResidual(run, segments, weights, kinematics);
    return new ceres::AutoDiffCostFunction<ModelSegmentResidual, ceres::DYNAMIC, K::kNumParameters>(
        functor, functor->NumResiduals());
  }

 private:
  const AlignedRun& run_;
  const std::vector<Segment>& segments_;
  ResidualWeights weights_;
  K kinematics_;
  std::vector<std::size_t> marks_;
};

template <class K>
class KinematicModel : public RobotModelInterface {
 public:
  using Kinematics = K;

  // K's prepared parameters behind the PreparedKinematics interface.
  template <typename T>
  class Prepared final : public PreparedKinematics<T> {
   public:
    Prepared(const K& kinematics, const T* p)
        : kinematics_(kinematics), prepared_(kinematics.Prepare(p)) {}
    void Step(const T* values, double dt, T* dx, T* dy, T* dtheta) const override {
      kinematics_.BodyStep(prepared_, values, dt, dx, dy, dtheta);
    }

   private:
    const K& kinematics_;
    decltype(std::declval<const K&>().Prepare(static_cast<const T*>(nullptr))) prepared_;
  };

  explicit KinematicModel(Robot robot, K kinematics = K())
      : robot_(std::move(robot)), kinematics_(std::move(kinematics)) {}

  const Robot& robot() const override { return robot_; }
  const K& kinematics() const { return kinematics_; }

  Pose2d Replay(const double* p, const EncoderSamples& samples, std::size_t begin, std::size_t end,
                const Pose2d& start, const PoseVisitor& visit = nullptr) const override {
    CheckChannels(samples);
    if (!visit) return ReplayKinematics(kinematics_, p, samples, begin, end, start);
    return ReplayKinematics(kinematics_, p, samples, begin, end, start,
                            [&visit](std::size_t k, const Pose2d& pose) { visit(k, pose); });
  }

  ceres::CostFunction* FinalPoseCost(const AlignedRun& run,
                                     const ResidualWeights& weights) const override {
    CheckChannels(run.samples);
    if constexpr (FinalPoseJacobianKindOf<K>::value == FinalPoseJacobianKind::kAutodiff) {
      return ModelFinalPoseResidual<K>::Create(run, weights, kinematics_);
    } else {
      return new FinalPoseJacobianCost<K>(run, weights, kinematics_);
    }
  }

  ceres::CostFunction* SegmentCost(const AlignedRun& run, const std::vector<Segment>& segments,
                                   const ResidualWeights& weights) const override {
    CheckChannels(run.samples);
    if constexpr (FinalPoseJacobianKindOf<K>::value == FinalPoseJacobianKind::kAutodiff) {
      return ModelSegmentResidual<K>::Create(run, segments, weights, kinematics_);
    } else {
      return new SegmentJacobianCost<K>(run, segments, weights, kinematics_);
    }
  }

  bool SegmentResidualsAlikeWithJacobians() const override {
    return FinalPoseJacobianKindOf<K>::value != FinalPoseJacobianKind::kAutodiff;
  }

  // The body step reads robot().NumChannels() values per row: samples of another width would be
  // read out of bounds. A check that fires in release builds too (STYLE.md habit 7).
  void CheckChannels(const EncoderSamples& samples) const {
    if (samples.num_channels() != robot_.NumChannels()) {
      throw std::invalid_argument("samples with " + std::to_string(samples.num_channels()) +
                                  " channels replayed by a " + robot_.model + " robot with " +
                                  std::to_string(robot_.NumChannels()));
    }
  }

  bool StepMatrix(const double* p, double* m) const override {
    if constexpr (FinalPoseJacobianKindOf<K>::value != FinalPoseJacobianKind::kLinearInChannels) {
      return RobotModelInterface::StepMatrix(p, m);
    } else {
      // Column i of M: the step of a unit rate on channel i over 1 s (exact: the step is linear).
      constexpr int N = K::kNumChannels;
      const auto prepared = kinematics_.Prepare(p);
      for (int i = 0; i < N; ++i) {
        std::array<double, N> unit{};
        unit[i] = 1.0;
        kinematics_.BodyStep(prepared, unit.data(), 1.0, &m[i], &m[N + i], &m[2 * N + i]);
      }
      return true;
    }
  }

  bool ChannelsForTwist(const double* p, const Twist& twist, double* values) const override {
    return kinematics_.ChannelsForTwist(p, twist, values);
  }

  std::unique_ptr<const PreparedKinematics<double>> PrepareKinematics(
      const double* p) const override {
    return std::make_unique<Prepared<double>>(kinematics_, p);
  }
  std::unique_ptr<const PreparedKinematics<EffectJet>> PrepareKinematics(
      const EffectJet* p) const override {
    return std::make_unique<Prepared<EffectJet>>(kinematics_, p);
  }

 protected:
  Robot robot_;
  K kinematics_;
};

}  // namespace fitcal
