#pragma once
// A pose source on a mount, for every model: the ground truth tracks a frame X (a LiDAR or visual
// odometry, a SLAM pose, a tracker) fixed on the body at base_T_sensor = X = (x, y, yaw), not the
// kinematic centre. The robot YAML declares its nominal guess,
//   ground_truth_frame: {x_m: 1.5, y_m: 0.0, yaw_deg: 0.0}
// and MountedModel is the model `inner` with three more parameters, ground_truth_x,
// ground_truth_y, ground_truth_yaw, fitted, held, tied and bounded like any other (bounds:
// ground_truth_x_m, ground_truth_y_m, ground_truth_yaw_deg; wide by default).
//
// The frame's motion: with D the base's odometry motion from a run's start (odometry/replay.h),
// the sensor moves by
//   S_0^-1 S_k = X^-1 D_k X                                   (Censi et al., T-RO 2013, Eq. 3)
// and per encoder interval the sensor's body step is the base's step d conjugated, X^-1 d X (the
// product of conjugated steps is the conjugated product, so the replay of the steps and the
// transform of the whole motion agree exactly). Every residual already compares motion from the
// run's start (the final pose replayed from the ground truth's start pose, the segments and the
// track from their window's start), so the ground truth may live in any world frame, the
// sensor's own start included.
//
// What the runs can determine: a robot that cannot move sideways (differential drive, tricycle)
// has a point its wheels fix - the one with no sideways velocity - so x, y and yaw of a frame
// seen from it are determined by turning runs. A robot that can move sideways has no such point:
// its reference point is wherever its wheel distances put it, and a shift of the pose source is a
// change of them (omni3: R_i' = R_i - e_x cos delta_i - e_y sin delta_i). Its x and y are held at
// the nominal, with that reason (Robot::held); what remains is left to the direction analysis
// (fit/determined_directions.h) like any parameter. A guess the wheel distances cannot absorb
// within their bounds is the exception: WithSidewaysMountFreed, and calibrate/calibrate.cc.

#include <yaml-cpp/yaml.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "models/model_interface.h"

namespace fitcal {

// base_T_sensor; angles in radians.
struct GroundTruthFrame {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
};

// X^-1 d X for X = (x, y, yaw) (header): translation R(-yaw) (t_d + R(theta_d) t_X - t_X).
template <typename T, typename M>
Pose2<T> ConjugateByMount(const M* mount, const Pose2<T>& d) {
  using std::cos;
  using std::sin;
  const T cd = cos(d.theta), sd = sin(d.theta);
  const T ax = d.x + cd * mount[0] - sd * mount[1] - mount[0];
  const T ay = d.y + sd * mount[0] + cd * mount[1] - mount[1];
  const M cm = cos(mount[2]), sm = sin(mount[2]);
  return {cm * ax + sm * ay, -sm * ax + cm * ay, d.theta};
}

class MountedModel final : public RobotModelInterface {
 public:
  static constexpr int kNumMountParameters = 3;  // x, y, yaw

  // `bounds` (3 intervals, SI and rad) around the nominal `frame`. `hold_sideways` holds x and y
  // of a robot that moves sideways (the header's gauge).
  MountedModel(RobotModelPtr inner, const GroundTruthFrame& frame,
               const std::vector<Interval>& bounds, bool hold_sideways = true);

  // The same model with x and y free where they are held as the gauge (then the direction
  // analysis holds the gauge's direction at the nominal, wheel distances and mount together);
  // nullptr where nothing is held that way.
  RobotModelPtr WithSidewaysMountFreed() const;

  const Robot& robot() const override { return robot_; }
  const RobotModelInterface& inner() const { return *inner_; }
  // Index in p of ground_truth_x (then y, yaw).
  int MountIndex() const { return inner_->robot().NumParameters(); }

  Pose2d Replay(const double* p, const EncoderSamples& samples, std::size_t begin, std::size_t end,
                const Pose2d& start, const PoseVisitor& visit = nullptr) const override;
  ceres::CostFunction* FinalPoseCost(const AlignedRun& run,
                                     const ResidualWeights& weights) const override;
  ceres::CostFunction* SegmentCost(const AlignedRun& run, const std::vector<Segment>& segments,
                                   const ResidualWeights& weights) const override;
  // MountedCost maps the inner segment cost's residuals through the same Jets with and without
  // Jacobians, so its residuals are alike exactly where the inner model's are.
  bool SegmentResidualsAlikeWithJacobians() const override {
    return inner_->SegmentResidualsAlikeWithJacobians();
  }
  std::unique_ptr<const PreparedKinematics<double>> PrepareKinematics(
      const double* p) const override;
  std::unique_ptr<const PreparedKinematics<EffectJet>> PrepareKinematics(
      const EffectJet* p) const override;
  // The base's channels for the base's twist: simulators and the motion analysis command the
  // robot, not its sensor.
  bool ChannelsForTwist(const double* p, const Twist& twist, double* values) const override {
    return inner_->ChannelsForTwist(p, twist, values);
  }
  using RobotModelInterface::RobotYaml;
  // The inner model's YAML with `ground_truth_frame:` and the frame's bounds added.
  std::string RobotYaml(const std::vector<double>& p,
                        const std::vector<effects::EffectValue>& effects,
                        const std::string& calibration_block) const override;
  std::vector<ChannelMapping> CandidateMiswirings() const override {
    return inner_->CandidateMiswirings();
  }
  std::vector<ClosedFormCalibration> ClosedForms(
      const std::vector<AlignedRun>& training) const override;

 private:
  RobotModelPtr inner_;
  Robot robot_;
};

// The robot the controller drives: `model` itself, or the model inside a MountedModel (whose
// parameters are the first ones of the mounted model's).
const RobotModelInterface& BaseModel(const RobotModelInterface& model);

// The indices of the frame's three numbers (ground_truth_x, _y, _yaw); empty for a robot
// without the frame.
std::vector<int> MountParameterIndices(const Robot& robot);
// Whether parameter k is the ground-truth frame's x or y.
bool IsMountPosition(const Robot& robot, int k);

// One line saying which of the frame's numbers the fit determined, which it fitted but the runs
// leave along an open direction (not_determined: per parameter, fit/determined_directions.h; may
// be empty), and which it held (held: per parameter, the fit's holds), with `held_reason` (a
// closed form's), else the model's reason (--hold or a held direction without one); "" for a
// robot without the frame.
std::string GroundTruthFrameLine(const Robot& robot, const std::vector<bool>& held,
                                 const std::string& held_reason = "",
                                 const std::vector<bool>& not_determined = {});

// The ground truth's mount held at its guess because the runs cannot tell it from the wheels'
// geometry (held: per parameter; an omni robot's x and y): a guess that is off moves into the
// wheel distances, which may be what ended on a bound - "; the ground truth's mount is held at
// its guess (...)", said beside the bound with the values; "" when no number of the frame is held.
std::string HeldMountNote(const Robot& robot, const std::vector<double>& parameters,
                          const std::vector<bool>& held);

// The robot YAML's `ground_truth_frame:` (and its bounds under `bounds:`), read from `root` and
// removed from it, so that the model's own reader sees its schema only. Returns `inner` itself
// when the key is absent. InputError (file:line) for a malformed frame or bounds.
RobotModelPtr ApplyGroundTruthFrame(YAML::Node root, const std::string& path,
                                    const std::function<RobotModelPtr(const YAML::Node&)>& read);

}  // namespace fitcal
