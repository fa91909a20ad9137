#pragma once
// An omni3 robot on the model seam: Palacin's kinematics (omni3_kinematics.h) and the robot YAML
// schema of README.md "Data set format" (wheels with distance_m, radius_m, angle_deg; bounds per
// group, angle bounds relative to each wheel's nominal angle, Eq. 16).

#include <yaml-cpp/yaml.h>

#include <string>

#include "models/kinematic_model.h"
#include "models/omni/omni_model.h"
#include "models/omni3/omni3_kinematics.h"

namespace fitcal {

class Omni3Model : public KinematicModel<Omni3Kinematics> {
 public:
  // angle_offset: the YAML's angle bounds relative to the nominal angles (kept to write back).
  Omni3Model(Robot robot, Interval angle_offset_rad)
      : KinematicModel(std::move(robot)), angle_offset_rad_(angle_offset_rad) {}

  // The angle bounds relative to the nominal angles (Eq. 16), as the YAML states them.
  const Interval& angle_offset_rad() const { return angle_offset_rad_; }

  using RobotModelInterface::RobotYaml;
  std::string RobotYaml(const std::vector<double>& p,
                        const std::vector<effects::EffectValue>& effects,
                        const std::string& calibration_block) const override;

 private:
  Interval angle_offset_rad_;
};

// The generic description of an omni3 robot with these wheel names: channels "w_<name>" /
// "ticks_<name>", parameters R_<name>, r_<name>, delta_<name> in Eq. 15 order.
Robot Omni3RobotDescription(const std::string& name, const std::vector<std::string>& wheel_names);

inline constexpr const char* kOmni3ExampleYaml = R"(model: omni3
name: example_omni3
wheels:
  - {name: a, distance_m: 0.195, radius_m: 0.148, angle_deg: 60.0}
  - {name: b, distance_m: 0.195, radius_m: 0.148, angle_deg: 180.0}
  - {name: c, distance_m: 0.195, radius_m: 0.148, angle_deg: 300.0}
bounds:
  distance_m: [0.170, 0.220]
  radius_m: [0.138, 0.158]
  angle_offset_deg: [-2.0, 2.0]
)";

RobotModelPtr ReadOmni3Model(const YAML::Node& root, const std::string& path);

// An omni3 model made in the models library, so that its replay on Ceres Jets is compiled here
// and not in an instrumented caller (models/diff_drive/diff_drive_model.h, MakeDiffDriveModel,
// says why; tests/checks/instrumented_templates.cmake keeps it so).
RobotModelPtr MakeOmni3Model(Robot robot, Interval angle_offset_rad);

// The bounds of the nine parameters (Eq. 15 order) in the box of the YAML's `bounds:`: one
// interval for every R_i, one for every r_i, the angle bounds relative to each nominal delta_i
// (Eq. 16).
std::vector<Interval> Omni3ParameterBounds(const std::vector<double>& nominal,
                                           const OmniBounds& box);

}  // namespace fitcal
