#pragma once
// A differential-drive robot on the model seam: the kinematics of diff_drive_kinematics.h, the
// robot YAML schema below and UMBmark (umbmark.h) as its classical calibration.
//
// Robot YAML: kDiffDriveExampleYaml below (wheels in encoder channel order, bounds absolute),
// with optional `encoder:` and `effects:` blocks (io/robot_yaml_blocks.h).
//
// Which wheel is which: a wheel named `right` or `left` is on that side; a wheel with any other
// name needs `side: right` or `side: left` (e.g. `{name: a, side: left, radius_m: 0.05}`). One
// wheel on each side, in either order; the channels and the parameters follow the YAML's order:
// parameters r_<name 0>, r_<name 1>, wheel_separation; channels w_<name> (rad/s) or
// ticks_<name>. A positive wheel rate drives the robot forward.
//
// Strict: unknown keys, a missing or third wheel, two wheels on one side, a radius or separation
// that is not positive, bounds that are not positive or do not contain the nominal values are
// io::InputError with the file and line.

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "models/diff_drive/diff_drive_kinematics.h"
#include "models/kinematic_model.h"

namespace fitcal {

// The generic description of a differential drive with these wheel names (YAML order): channels
// "w_<name>" / "ticks_<name>", parameters r_<name 0>, r_<name 1>, wheel_separation.
Robot DiffDriveRobotDescription(const std::string& name,
                                const std::vector<std::string>& wheel_names);

// The robot YAML of a differential drive with parameters p and `effects`; right_channel: 0 or 1.
std::string DiffDriveRobotYaml(const Robot& robot, int right_channel, const std::vector<double>& p,
                               const std::vector<effects::EffectValue>& effects,
                               const std::string& calibration_block);

// UMBmark (Borenstein & Feng 1996, umbmark.h) from the CW and CCW squares among the training runs
// (trajectory label containing "square"); nullopt without at least one of each. The method of
// diff_drive's closed form (diff_drive_extras.cc).
std::optional<ClosedFormCalibration> DiffDriveUmbmark(const RobotModelInterface& model,
                                                      const std::vector<AlignedRun>& training);

template <int kRightChannel>
class DiffDriveModelT : public KinematicModel<DiffDriveKinematicsT<kRightChannel>> {
 public:
  static constexpr int kRight = kRightChannel;
  static constexpr int kLeft = 1 - kRightChannel;

  explicit DiffDriveModelT(Robot robot)
      : KinematicModel<DiffDriveKinematicsT<kRightChannel>>(std::move(robot)) {}

  using RobotModelInterface::RobotYaml;
  std::string RobotYaml(const std::vector<double>& p,
                        const std::vector<effects::EffectValue>& effects,
                        const std::string& calibration_block) const override {
    return DiffDriveRobotYaml(this->robot_, kRightChannel, p, effects, calibration_block);
  }
};

// The right wheel first.
using DiffDriveModel = DiffDriveModelT<0>;

// An example robot: the OptiOdom differential drive's nominal values, right wheel first.
inline constexpr const char* kDiffDriveExampleYaml = R"(model: diff_drive
name: example_diff_drive
wheels:
  - {name: right, radius_m: 0.042}
  - {name: left, radius_m: 0.042}
wheel_separation_m: 0.200
bounds: {radius_m: [0.038, 0.046], wheel_separation_m: [0.180, 0.220]}
)";

// The channel index of the right wheel of a diff_drive model (0 or 1); -1 for another model.
int DiffDriveRightChannel(const RobotModelInterface& model);

RobotModelPtr ReadDiffDriveModel(const YAML::Node& root, const std::string& path);

// The model of a described robot whose wheels are right then left. Made here, not by the caller:
// the model's templates (its replay on Jets, the residual functors) are then instantiated in the
// models library only; a command file that instantiated them gave the sanitizer build's fitcal
// its instrumented -O1 copies of the fit's inner loop (30x slower; CMakeLists.txt,
// fitcal_sanitized).
RobotModelPtr MakeDiffDriveModel(Robot robot);

}  // namespace fitcal
