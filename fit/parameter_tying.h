#pragma once
// Parameter tying for every model on the seam: groups of parameters that share one value, and
// parameters held at their nominal values. OptiOdom's reduced model of an omni3 (Sousa et al.
// 2022: one common wheel distance, three radii, the angles fixed) is
//   groups {R_a, R_b, R_c}, held {delta_a, delta_b, delta_c};
// a differential drive with one radius for both wheels is the group {r_left, r_right}.
// Parameters are named as the model names them (robot().parameters, ParameterIndex in
// models/model_interface.h), never by their position in p.
//
// How: a reparametrisation. TiedModel is the model seen through p = A q: q has one value per
// group and one per untied parameter, A (n x m) has a one in row k and column "group of k".
// Its cost functions wrap the inner model's (J_q = J_p A), so FitModel's active set, covariance,
// clock offsets and direction analysis run unchanged on q, with every residual kind (final pose,
// segment, track). Held parameters stay parameters of q and join Robot::held, the hold every fit
// already honours (SubsetManifold, zero covariance rows). The fit's result is mapped back by
// ExpandTiedResult (fit/model_fit.h): p = A q, C_p = A C_q A^T, so a tied parameter's sigma is
// its shared value's.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "models/model_interface.h"

namespace fitcal {

struct ParameterTying {
  std::vector<std::vector<std::string>> groups;  // each: two or more names sharing one value
  std::vector<std::string> held;                 // names held at their nominal values
  bool empty() const { return groups.empty() && held.empty(); }
};

// "" when `tying` can be applied to `robot`, otherwise one line saying what is wrong: an unknown
// name (with the robot's names), a name used twice, a group of fewer than two, a tied parameter
// the model holds, or tied parameters whose bounds do not overlap.
std::string CheckTying(const Robot& robot, const ParameterTying& tying);

// The model `inner` with parameters q (header comment). `inner` must outlive it.
class TiedModel final : public RobotModelInterface {
 public:
  // Throws std::invalid_argument(CheckTying's line) when the tying does not apply.
  TiedModel(const RobotModelInterface& inner, const ParameterTying& tying);

  const Robot& robot() const override { return robot_; }
  const RobotModelInterface& inner() const { return inner_; }
  // Column of A for each of inner's parameters: p[k] = q[GroupOf(k)].
  int GroupOf(int k) const { return group_of_[k]; }
  Eigen::MatrixXd Basis() const;  // A, n x m
  std::vector<double> Expand(const double* q) const;
  // The mean of each group's members (a tied start, e.g. the nominal, becomes one value).
  std::vector<double> Reduce(const std::vector<double>& p) const;

  Pose2d Replay(const double* q, const EncoderSamples& samples, std::size_t begin, std::size_t end,
                const Pose2d& start, const PoseVisitor& visit = nullptr) const override;
  ceres::CostFunction* FinalPoseCost(const AlignedRun& run,
                                     const ResidualWeights& weights) const override;
  ceres::CostFunction* SegmentCost(const AlignedRun& run, const std::vector<Segment>& segments,
                                   const ResidualWeights& weights) const override;
  std::unique_ptr<const PreparedKinematics<double>> PrepareKinematics(
      const double* q) const override;
  std::unique_ptr<const PreparedKinematics<EffectJet>> PrepareKinematics(
      const EffectJet* q) const override;
  // The tied cost passes the inner cost's residuals through (TiedCost).
  bool SegmentResidualsAlikeWithJacobians() const override {
    return inner_.SegmentResidualsAlikeWithJacobians();
  }
  bool StepMatrix(const double* q, double* m) const override;
  bool ChannelsForTwist(const double* q, const Twist& twist, double* values) const override;
  using RobotModelInterface::RobotYaml;
  std::string RobotYaml(const std::vector<double>& q,
                        const std::vector<effects::EffectValue>& effects,
                        const std::string& calibration_block) const override;
  std::vector<ChannelMapping> CandidateMiswirings() const override {
    return inner_.CandidateMiswirings();
  }

 private:
  template <typename T>
  std::vector<T> ExpandAs(const T* q) const;
  ceres::CostFunction* Wrap(ceres::CostFunction* inner_cost) const;

  const RobotModelInterface& inner_;
  Robot robot_;
  std::vector<int> group_of_;
};

}  // namespace fitcal
