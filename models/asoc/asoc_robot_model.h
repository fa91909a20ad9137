#pragma once
// An ASOC vehicle (Doebbler et al.: three active split offset castors) on the model seam: the
// kinematics of asoc_kinematics.h, the robot YAML of models/asoc/asoc_files.h (`model: asoc`), the
// closed-form calibration of Eq. 1-9 (asoc_geometric.h) as a candidate of the result gate, and the
// miswirings an ASOC base can have.
//
// Channels, castor by castor (castor names from the YAML): `<castor>_a`, `<castor>_b` (wheel
// rates, CSV columns `w_<castor>_a` or `ticks_<castor>_a`), `pivot_<castor>` (pivot encoder angle,
// rad, a reading per row). ASOC's own encoder files (cumulative wheel angles) are converted to
// these on load (models/asoc/asoc_files.h AsocEncoderLogAsChannels).
// Parameters, castor by castor: r_c_<castor>, r_w1_<castor>, r_w2_<castor>, d_1_<castor>,
// d_2_<castor>, beta_<castor> (asoc::Vehicle::ToArray order). The known pivot layout fixes the
// body frame (asoc_kinematics.h); each castor's r_c and beta are held, since odometry sees a castor
// only through the 4 numbers of its wheel-to-pivot map (asoc_robot_model.cc) - the closed form
// measures both (Eq. 2, 3).

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "models/asoc/asoc_files.h"
#include "models/asoc/asoc_geometric.h"
#include "models/asoc/asoc_kinematics.h"
#include "models/kinematic_model.h"

namespace fitcal {

class AsocModel : public KinematicModel<AsocKinematics> {
 public:
  AsocModel(Robot robot, io::AsocRobot asoc, AsocKinematics kinematics)
      : KinematicModel(std::move(robot), std::move(kinematics)), asoc_(std::move(asoc)) {}

  using RobotModelInterface::RobotYaml;
  std::string RobotYaml(const std::vector<double>& p,
                        const std::vector<effects::EffectValue>& effects,
                        const std::string& calibration_block) const override;

  // Doebbler Eq. 1-9 from every hold run (`hold_<j>_cw` / `hold_<j>_ccw`) among the training
  // runs: the method of asoc's closed form (asoc_extras.cc).
  std::optional<ClosedFormCalibration> Geometric(const std::vector<AlignedRun>& training) const;

  // Per castor: wheels a and b swapped, both wheels' signs flipped (a module's motor polarity),
  // each wheel's sign flipped, the pivot encoder's sign flipped; per pair of castors: the whole
  // castor cables swapped, the pivot encoders alone swapped. The identity first.
  std::vector<ChannelMapping> CandidateMiswirings() const override;

  const io::AsocRobot& asoc() const { return asoc_; }
  // The same robot replayed by another of Doebbler's odometry algorithms (asoc_kinematics.h).
  RobotModelPtr WithOdometry(const AsocOdometryOptions& odometry) const;

 private:
  io::AsocRobot asoc_;
};

// The simulated one-third-scale prototype (tests/asoc_simulation.h PrototypeVehicle).
inline constexpr const char* kAsocExampleYaml = R"(model: asoc
name: example_asoc
pivot_distance_m: 0.5196152423
pivot_resolution_deg: 0.07
castors:
  - {name: "1", pivot_radius_m: 0.3, pivot_angle_deg: 0, offset_m: 0.08,
     wheel_radius_m: [0.04, 0.04], wheel_offset_m: [0.06, 0.06], encoder_bias_deg: 0}
  - {name: "2", pivot_radius_m: 0.3, pivot_angle_deg: 120, offset_m: 0.08,
     wheel_radius_m: [0.04, 0.04], wheel_offset_m: [0.06, 0.06], encoder_bias_deg: 0}
  - {name: "3", pivot_radius_m: 0.3, pivot_angle_deg: 240, offset_m: 0.08,
     wheel_radius_m: [0.04, 0.04], wheel_offset_m: [0.06, 0.06], encoder_bias_deg: 0}
)";

RobotModelPtr ReadAsocModel(const YAML::Node& root, const std::string& path);

}  // namespace fitcal
