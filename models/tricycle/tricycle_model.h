#pragma once
// A tricycle robot on the model seam: the kinematics of tricycle_kinematics.h and its robot YAML
//
//   model: tricycle
//   name: forklift_3
//   traction_wheel: {radius_m: 0.0325}      # optional `name:` (default "traction")
//   wheelbase_m: 0.15                        # traction wheel to the rear axle's centre
//   steering_offset_deg: 0.0                 # true steering = measured + offset
//   bounds: {radius_m: [lo, hi], wheelbase_m: [lo, hi], steering_offset_deg: [lo, hi]}
//   encoder: {ticks_per_rev: 1600, cumulative: false}   # optional, for the traction ticks
//   effects: [...]                           # optional (io/robot_yaml_blocks.h)
//
// Bounds are absolute (the steering offset is itself an offset). Encoder channels: the traction
// wheel (`w_<name>` rad/s or `ticks_<name>`) and the steering angle (`steering`, rad, one reading
// per row at the row's time).

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "models/kinematic_model.h"
#include "models/tricycle/tricycle_kinematics.h"
#include "odometry/run_log.h"

namespace fitcal {

class TricycleModel : public KinematicModel<TricycleKinematics> {
 public:
  explicit TricycleModel(Robot robot) : KinematicModel(std::move(robot)) {}

  using RobotModelInterface::RobotYaml;
  std::string RobotYaml(const std::vector<double>& p,
                        const std::vector<effects::EffectValue>& effects,
                        const std::string& calibration_block) const override;

  // The loader's hook for model-specific checks of a log (proposed as a virtual of
  // RobotModelInterface): the steering channel is present, in [-pi, pi] and not ticks
  // (tricycle_checks.h). Throws io::InputError.
  void CheckSamples(const EncoderLog& log, const std::string& path) const;
};

// The generic description of a tricycle: channels (traction `w_<name>`/`ticks_<name>`, steering
// `steering`) and parameters r_<name>, wheelbase, steering_offset in TricycleKinematics order;
// nominal and bounds empty.
Robot TricycleRobotDescription(const std::string& name, const std::string& traction_name);

// The OptiOdom tricycle's nominal robot (data sheet values, tools/optiodom_robots.cc).
inline constexpr const char* kTricycleExampleYaml = R"(model: tricycle
name: example_tricycle
traction_wheel: {radius_m: 0.0325}
wheelbase_m: 0.15
steering_offset_deg: 0.0
bounds: {radius_m: [0.030, 0.035], wheelbase_m: [0.13, 0.17], steering_offset_deg: [-10.0, 10.0]}
)";

RobotModelPtr ReadTricycleModel(const YAML::Node& root, const std::string& path);

}  // namespace fitcal
