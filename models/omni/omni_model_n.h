#pragma once
// The model of N omni or mecanum wheels (omni_model.h): the template definitions behind
// BuildOmniModel<N> (omni_model_build.h). Included only by omni_model_<N>.cc, one translation unit
// per wheel count: each KinematicModel<OmniKinematics<N>> instantiates the replay, the final-pose
// and segment costs and the effect replay on Jets of 3 N parameters, and the six of them in one
// file were its longest compile step (108 s in Release, 210 s under the sanitizers), which one
// core had to do alone. What does not depend on N is compiled once, in omni_model.cc
// (docs/tests.md: the CPU times).

#include <ceres/jet.h>

#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/robot_yaml_blocks.h"
#include "io/yaml_text.h"
#include "models/kinematic_model.h"
#include "models/omni/omni_kinematics.h"
#include "models/omni/omni_model_build.h"

namespace fitcal {
namespace omni_model_internal {

template <int N>
class OmniModel : public KinematicModel<OmniKinematics<N>> {
 public:
  OmniModel(Robot robot, const OmniKinematics<N>& kinematics, Interval angle_offset_rad)
      : KinematicModel<OmniKinematics<N>>(std::move(robot), kinematics),
        angle_offset_rad_(angle_offset_rad) {}

  using RobotModelInterface::RobotYaml;
  std::string RobotYaml(const std::vector<double>& p,
                        const std::vector<effects::EffectValue>& effects,
                        const std::string& calibration_block) const override;

 private:
  Interval angle_offset_rad_;
};

template <int N>
std::string OmniModel<N>::RobotYaml(const std::vector<double>& p,
                                    const std::vector<effects::EffectValue>& effects,
                                    const std::string& calibration_block) const {
  using K = OmniKinematics<N>;
  const Robot& robot = this->robot_;
  const K& kinematics = this->kinematics_;
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  out << YAML::BeginMap;
  out << YAML::Key << "model" << YAML::Value << "omni";
  out << YAML::Key << "name" << YAML::Value << io::YamlText(robot.name);
  out << YAML::Key << "wheels" << YAML::Value << YAML::BeginSeq;
  for (int i = 0; i < N; ++i) {
    const double angle_rad = p[K::kAngleIndex + i];
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << io::YamlText(robot.channels[i].name);
    out << YAML::Key << "distance_m" << YAML::Value << p[K::kDistanceIndex + i];
    out << YAML::Key << "angle_deg" << YAML::Value << RadToDeg(angle_rad);
    out << YAML::Key << "radius_m" << YAML::Value << p[K::kRadiusIndex + i];
    out << YAML::Key << "drive_angle_deg" << YAML::Value
        << RadToDeg(angle_rad + kinematics.mount[i].drive_offset_rad);
    out << YAML::Key << "roller_angle_deg" << YAML::Value
        << RadToDeg(kinematics.mount[i].roller_rad);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "bounds" << YAML::Value << YAML::BeginMap;
  io::EmitBoundsPair(out, "distance_m", robot.bounds[K::kDistanceIndex], 1.0);
  io::EmitBoundsPair(out, "radius_m", robot.bounds[K::kRadiusIndex], 1.0);
  io::EmitBoundsPair(out, "angle_offset_deg", angle_offset_rad_, 180.0 / M_PI);
  out << YAML::EndMap;
  io::EmitEncoderAndEffects(out, robot, effects);
  out << YAML::EndMap;
  std::string text = std::string(out.c_str()) + "\n";
  if (calibration_block.empty()) return text;
  // The forward matrix F (v = F w, rad/s in, m/s and rad/s out) for firmware that takes it.
  const typename K::template ForwardMatrixT<double> f = kinematics.Prepare(p.data());
  return text + calibration_block + io::CalibrationMatrixYaml("forward_kinematic_matrix", f) + "\n";
}

// The wheels' kinematic matrix at the nominal must have rank 3, else some motion turns no wheel.
// The yaw column is scaled by the mean distance so that the three columns share a unit.
template <int N>
void CheckFullRank(const OmniKinematics<N>& kinematics, const std::vector<double>& nominal,
                   const std::vector<OmniWheel>& wheels) {
  Eigen::Matrix<double, N, 3> j = kinematics.KinematicMatrix(nominal.data());
  double mean_distance_m = 0.0;
  for (const OmniWheel& w : wheels) mean_distance_m += w.distance_m / N;
  j.col(2) /= mean_distance_m;
  const Eigen::JacobiSVD<Eigen::Matrix<double, N, 3>> svd(j, Eigen::ComputeFullV);
  const Eigen::Vector3d s = svd.singularValues();
  if (s(2) > kRankTolerance * s(0)) return;
  const Eigen::Vector3d v = svd.matrixV().col(2);
  std::string names;
  for (const OmniWheel& w : wheels) names += (names.empty() ? "" : ", ") + w.name;
  char motion[160];
  std::snprintf(motion, sizeof motion, "(vx, vy, omega R) = (%.3g, %.3g, %.3g)", v(0), v(1), v(2));
  throw std::invalid_argument("wheels " + names +
                              ": the kinematic matrix is not of full rank; no wheel senses the "
                              "motion " +
                              motion);
}

// The Jacobian of vec(F(p) J(p0)) with respect to p at p = p0, columns scaled by each
// parameter's RelativeScale (robot.h): 9 x 3N.
template <int N>
Eigen::MatrixXd TwistJacobian(const OmniKinematics<N>& kinematics, const Robot& robot) {
  constexpr int kP = 3 * N;
  using Jet = ceres::Jet<double, kP>;
  std::array<Jet, kP> p;
  for (int k = 0; k < kP; ++k) p[k] = Jet(robot.nominal[k], k);
  const auto f = kinematics.Prepare(p.data());
  const Eigen::Matrix<double, N, 3> j0 = kinematics.KinematicMatrix(robot.nominal.data());
  Eigen::MatrixXd g(9, kP);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      Jet e(0.0);
      for (int i = 0; i < N; ++i) e += f(r, i) * j0(i, c);
      for (int k = 0; k < kP; ++k) {
        g(3 * r + c, k) = e.v[k] * robot.parameters[k].RelativeScale(robot.nominal[k]);
      }
    }
  }
  return g;
}

// The gauge of N wheels (omni_model.cc: GaugeOfTwistJacobian): what does not depend on N is
// compiled once there, not in each of the six translation units.
template <int N>
std::vector<HeldParameter> OmniGauge(const OmniKinematics<N>& kinematics, const Robot& robot) {
  using K = OmniKinematics<N>;
  return GaugeOfTwistJacobian(TwistJacobian(kinematics, robot), robot,
                              {K::kAngleIndex, K::kDistanceIndex, K::kRadiusIndex}, N);
}

}  // namespace omni_model_internal

template <int N>
RobotModelPtr BuildOmniModel(Robot robot, const std::vector<OmniWheel>& wheels,
                             const OmniBounds& box) {
  OmniKinematics<N> kinematics;
  for (int i = 0; i < N; ++i) {
    kinematics.mount[i].drive_offset_rad = wheels[i].drive_angle_rad - wheels[i].angle_rad;
    kinematics.mount[i].roller_rad = wheels[i].roller_angle_rad;
  }
  omni_model_internal::CheckFullRank(kinematics, robot.nominal, wheels);
  robot.held = omni_model_internal::OmniGauge(kinematics, robot);
  return std::make_shared<omni_model_internal::OmniModel<N>>(std::move(robot), kinematics,
                                                             box.angle_offset_rad);
}

template <int N>
bool FillOmniWheelMounts(const RobotModelInterface& model, std::vector<OmniWheel>* wheels) {
  const auto* omni = dynamic_cast<const omni_model_internal::OmniModel<N>*>(&model);
  if (omni == nullptr) return false;
  const auto& mount = omni->kinematics().mount;
  for (int i = 0; i < N; ++i) {
    OmniWheel& w = (*wheels)[i];
    w.drive_angle_rad = w.angle_rad + mount[i].drive_offset_rad;
    w.roller_angle_rad = mount[i].roller_rad;
  }
  return true;
}

}  // namespace fitcal
