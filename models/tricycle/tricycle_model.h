#pragma once
// A tricycle robot on the model seam: the kinematics of tricycle_kinematics.h and its robot YAML,
// kTricycleExampleYaml below: traction_wheel takes an optional `name:` (default "traction"),
// wheelbase_m runs from the traction wheel to the rear axle's centre, true steering = gain x
// measured + offset with an optional steering_gain (a fourth parameter; bounds key
// steering_gain, default [gain / 10, gain x 10]); optional `encoder:` (the traction ticks) and
// `effects:` (io/robot_yaml_blocks.h).
//
// Bounds are absolute (the steering offset is itself an offset). Encoder channels: the traction
// wheel (`w_<name>` rad/s or `ticks_<name>`) and the steering angle (`steering`, rad, one reading
// per row at the row's time).

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "models/kinematic_model.h"
#include "models/tricycle/tricycle_kinematics.h"

namespace fitcal {

// The calibrated YAML of either kind (tricycle_model.cc).
std::string TricycleRobotYaml(const Robot& robot, const std::vector<double>& p,
                              const std::vector<effects::EffectValue>& effects,
                              const std::string& calibration_block);

// kHasGain: the robot YAML declares `steering_gain` (TricycleKinematicsT).
template <bool kHasGain>
class TricycleModelT : public KinematicModel<TricycleKinematicsT<kHasGain>> {
 public:
  explicit TricycleModelT(Robot robot)
      : KinematicModel<TricycleKinematicsT<kHasGain>>(std::move(robot)) {}

  using RobotModelInterface::RobotYaml;
  std::string RobotYaml(const std::vector<double>& p,
                        const std::vector<effects::EffectValue>& effects,
                        const std::string& calibration_block) const override {
    return TricycleRobotYaml(this->robot_, p, effects, calibration_block);
  }
};

using TricycleModel = TricycleModelT<false>;
using TricycleGainModel = TricycleModelT<true>;

// The generic description of a tricycle: channels (traction `w_<name>`/`ticks_<name>`, steering
// `steering`) and parameters r_<name>, wheelbase, steering_offset (and steering_gain with
// `with_gain`) in TricycleKinematicsT order; nominal and bounds empty.
Robot TricycleRobotDescription(const std::string& name, const std::string& traction_name,
                               bool with_gain = false);

// The OptiOdom tricycle's nominal robot (data sheet, interchange/optiodom/optiodom_robots.cc).
inline constexpr const char* kTricycleExampleYaml = R"(model: tricycle
name: example_tricycle
traction_wheel: {radius_m: 0.0325}
wheelbase_m: 0.15
steering_offset_deg: 0.0
bounds: {radius_m: [0.030, 0.035], wheelbase_m: [0.13, 0.17], steering_offset_deg: [-10.0, 10.0]}
)";

RobotModelPtr ReadTricycleModel(const YAML::Node& root, const std::string& path);

// The model of a robot described by TricycleRobotDescription (with or without the steering
// gain). Made in the models library so that the model's templates are instantiated there only
// (models/diff_drive/diff_drive_model.h, MakeDiffDriveModel, says why).
RobotModelPtr MakeTricycleModel(Robot robot);

}  // namespace fitcal
