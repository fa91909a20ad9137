#pragma once
// The seam every command goes through: one robot of one kinematic model. Commands, fits,
// diagnosis and validation see a robot only through this interface; a model is a folder
// models/<model>/ with its kinematics (one templated body-step functor, kinematic_model.h), its
// parameters and its YAML schema, registered by name in model_registry.h.
//
// What a model provides:
//   - robot(): its encoder channels, parameters, nominal values, bounds, held (gauge) parameters;
//   - the odometry: replay of encoder samples to poses with any parameter vector, on double, and
//     Ceres cost functions (autodiff through the same replay) for final poses and for segments;
//   - the inverse kinematics (channel values for a body twist), for simulators and for the
//     identifiability analysis' candidate runs;
//   - its calibrated YAML;
//   - the miswirings the wheel-order check should try (generated from its channels);
//   - optionally classical calibrations (closed forms) that compete with the fits.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "models/ceres_fwd.h"
#include "odometry/encoder_samples.h"
#include "odometry/pose2.h"
#include "odometry/robot.h"

namespace fitcal {

struct AlignedRun;

// How metres and radians are weighed against each other in a residual. The paper's CF uses 1
// and 1 (1 m counts like 1 rad); a sigma-whitened objective uses the ground truth's noise.
struct ResidualWeights {
  double position_sigma_m = 1.0;
  double heading_sigma_rad = 1.0;
};

// A body-frame velocity: forward, left (m/s) and yaw rate (rad/s).
struct Twist {
  double vx_m_s = 0.0;
  double vy_m_s = 0.0;
  double omega_rad_s = 0.0;
};

// A window [begin, end) of a run's samples and the ground truth's motion over it
// (models/pose_errors.h: the relative pose error of trajectory-evaluation tools).
struct Segment {
  std::size_t begin = 0;
  std::size_t end = 0;
  Pose2d ground_truth_start_T_end;  // Q_i^-1 Q_j
  double path_length_m = 0.0;       // ground-truth path length over the window
};

// One miswiring hypothesis: channel i of the model reads sign[i] * recorded column[i].
struct ChannelMapping {
  std::vector<int> column;
  std::vector<int> sign;
  bool IsIdentity() const {
    for (std::size_t i = 0; i < column.size(); ++i) {
      if (column[i] != static_cast<int>(i) || sign[i] != 1) return false;
    }
    return true;
  }
};

// A calibration computed by a classical method (UMBmark, ASOC's closed form): parameters and
// what produced them. It competes with the fits in the result gate.
struct ClosedFormCalibration {
  std::string method;  // "umbmark", "asoc-geometric"
  std::vector<double> parameters;
  std::string note;  // e.g. which runs it used
  // Its own 1-sigma per parameter where it measures one (ASOC: the spread of its estimates over
  // hold runs); empty, or NaN for a parameter it does not measure (left to the propagated
  // uncertainty, validation/propagated_uncertainty.h).
  std::vector<double> sigma = {};
};

// A model's kinematics at fixed parameters, for replays that transform the channel values or the
// body step on the way (the effect library, odometry/effects.h). T is double or EffectJet.
template <typename T>
class PreparedKinematics {
 public:
  virtual ~PreparedKinematics() = default;
  // The body-frame step (dx, dy, dtheta) of one encoder interval of length dt from its channel
  // values (robot().channels order), as the plain replay computes it.
  virtual void Step(const T* values, double dt, T* dx, T* dy, T* dtheta) const = 0;
};
// How a model's final-pose cost gets its Jacobian (models/final_pose_jacobian.h). A kinematics K
// (kinematic_model.h) declares `static constexpr FinalPoseJacobianKind kFinalPoseJacobianKind`;
// without it Ceres differentiates the whole replay in Jets.
enum class FinalPoseJacobianKind {
  kAutodiff,          // ceres::Jet through every sample of the replay
  kPerSampleStep,     // Jets on each body step only; the poses are integrated in double
  kLinearInChannels,  // the step is dt M(p) w: dM/dp once per evaluation, sums over the channels
};

// The scalar of the effect fit's dynamic autodiff (fit/effect_fit.cc differentiates four
// parameters per pass).
using EffectJet = ceres::Jet<double, 4>;

// Called with the sample index k and the pose after sample k.
using PoseVisitor = std::function<void(std::size_t k, const Pose2d& pose)>;

class RobotModelInterface {
 public:
  virtual ~RobotModelInterface() = default;

  virtual const Robot& robot() const = 0;

  // Dead reckoning of samples [begin, end) from `start` with parameters p (robot().parameters
  // order); visit, when set, sees every pose. Returns the final pose.
  virtual Pose2d Replay(const double* p, const EncoderSamples& samples, std::size_t begin,
                        std::size_t end, const Pose2d& start,
                        const PoseVisitor& visit = nullptr) const = 0;
  Pose2d ReplayFinalPose(const double* p, const EncoderSamples& samples,
                         const Pose2d& start) const {
    return Replay(p, samples, 0, samples.size(), start);
  }

  // The final-pose residual (Palacin Eq. 14) of one run, 3 residuals, autodiff; `run` must
  // outlive the cost function.
  virtual ceres::CostFunction* FinalPoseCost(const AlignedRun& run,
                                             const ResidualWeights& weights) const = 0;
  // The segment residuals of one run, 3 per segment; `run` and `segments` must outlive it.
  virtual ceres::CostFunction* SegmentCost(const AlignedRun& run,
                                           const std::vector<Segment>& segments,
                                           const ResidualWeights& weights) const = 0;

  // Whether SegmentCost's residuals are the same to the bit with and without Jacobians (an
  // analytic Jacobian whose poses are the plain replay's, models/segment_jacobian.h; not Ceres'
  // autodiff, whose Jets replay one sample at a time where the plain replay pairs them), so that
  // a residual-only request may be answered from an evaluation with Jacobians at the same point
  // (fit/track_residual.h OdometryMemo). False unless the model says so.
  virtual bool SegmentResidualsAlikeWithJacobians() const { return false; }

  // The kinematics at parameters p for the effect replay (PreparedKinematics above).
  virtual std::unique_ptr<const PreparedKinematics<double>> PrepareKinematics(
      const double* p) const = 0;
  virtual std::unique_ptr<const PreparedKinematics<EffectJet>> PrepareKinematics(
      const EffectJet* p) const = 0;

  // For a body step linear in the channel values, dt M(p) w (kLinearInChannels above): M at p,
  // 3 x robot().NumChannels() row-major (rows x, y, theta), for the final-pose kernel of the NLopt
  // search (odometry/linear_final_pose_kernel.h); false for other kinematics.
  virtual bool StepMatrix(const double* /*p*/, double* /*m*/) const { return false; }

  // Channel values (robot().channels order) that realise the body twist with parameters p, or
  // false when the model cannot drive that twist (e.g. a sideways motion of a differential drive).
  virtual bool ChannelsForTwist(const double* p, const Twist& twist, double* values) const = 0;

  // The calibrated robot YAML: the input schema with the values p and the effects `effects` (in
  // place of the ones robot() declares: a fit may refit, add or drop them), plus the calibration
  // block (calibration_block: YAML text, indented as a top-level map, or empty).
  virtual std::string RobotYaml(const std::vector<double>& p,
                                const std::vector<effects::EffectValue>& effects,
                                const std::string& calibration_block) const = 0;
  // The same with the effects robot() declares.
  std::string RobotYaml(const std::vector<double>& p, const std::string& calibration_block) const {
    return RobotYaml(p, robot().effects, calibration_block);
  }

  // The miswirings the wheel-order check scores (the identity first). Default: every permutation
  // within each group of channels of one kind and every sign pattern of the wheel channels,
  // capped to keep the check fast for many wheels.
  virtual std::vector<ChannelMapping> CandidateMiswirings() const;

  // Classical calibrations computed from the training runs: the closed forms the model registers
  // (model_extras.h ModelExtras::closed_forms), those the runs allow.
  virtual std::vector<ClosedFormCalibration> ClosedForms(
      const std::vector<AlignedRun>& training) const;
};

using RobotModelPtr = std::shared_ptr<const RobotModelInterface>;

// The name <-> index table of a model's parameters (issue 30): robot.parameters[k].name names
// p[k] ("r_left", "wheel_separation", "R_a", "delta_a"; per-wheel names end in the channel's
// name). Code outside models/ finds a parameter by its name, never by its position in p.
std::optional<int> ParameterIndex(const Robot& robot, const std::string& name);
// The same for a parameter the caller knows the model has: std::logic_error when it has not.
int RequireParameterIndex(const Robot& robot, const std::string& name);

}  // namespace fitcal
