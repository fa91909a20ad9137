#include "models/omni3/omni3_extras.h"

#include <cmath>
#include <cstdio>

#include "models/omni/flower_trajectories.h"
#include "models/omni/omni_extras.h"
#include "models/omni3/omni3_parameters.h"

namespace fitcal {

namespace {

std::string MatrixText(const Eigen::Matrix3d& m) {
  std::string out = "[";
  char value[64];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      std::snprintf(value, sizeof value, "%.4f", m(r, c));
      out += std::string(std::isnan(m(r, c)) ? "-" : value) + (c < 2 ? " " : "");
    }
    out += r < 2 ? "; " : "]";
  }
  return out;
}

// The M^-1 of Palacin Eq. 6: Table 4's column, and what firmware takes.
ParameterDisplay InverseKinematicMatrixColumns(const Robot& /*robot*/) {
  ParameterDisplay c;
  c.markdown_header = "M^-1";
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k)
      c.csv_names.push_back("m_inv_" + std::to_string(r) + std::to_string(k));
  }
  c.csv_values = [](const std::vector<double>& p) {
    const Eigen::Matrix3d m = omni3::InverseKinematicMatrix(p.data());
    std::vector<double> out;
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) out.push_back(m(r, k));
    }
    return out;
  };
  c.markdown = [](const std::vector<double>& p) {
    return MatrixText(omni3::InverseKinematicMatrix(p.data()));
  };
  return c;
}

// Table A1 as printed: the commands are the nominal robot's, whatever the truth.
std::vector<sim::TrajectorySpec> FlowerScenario(const Robot& /*nominal*/,
                                                const std::vector<double>& /*truth*/,
                                                int repetitions) {
  return sim::FlowerSpecs(sim::FlowerTrajectories(), repetitions);
}

omni3::Parameters Make(double r_a, double r_b, double r_c, double wr_a, double wr_b, double wr_c,
                       double d_a_deg, double d_b_deg, double d_c_deg) {
  omni3::Parameters p;
  p.distance_m = {r_a, r_b, r_c};
  p.radius_m = {wr_a, wr_b, wr_c};
  p.angle_rad = {d_a_deg * M_PI / 180.0, d_b_deg * M_PI / 180.0, d_c_deg * M_PI / 180.0};
  return p;
}

}  // namespace

namespace sim {

omni3::Parameters PalacinTable5Parameters() {
  return Make(0.218643, 0.215735, 0.216287, 0.155068, 0.151534, 0.152728, 59.7397, 179.6820,
              301.5735);
}

omni3::Parameters PalacinNominalParameters() {
  return Make(0.195, 0.195, 0.195, 0.148, 0.148, 0.148, 60.0, 180.0, 300.0);
}

Omni3Robot PalacinApr02Robot() {
  Omni3Robot robot;
  robot.name = "apr02";
  robot.nominal = PalacinNominalParameters();
  robot.bounds.distance_m = {0.170, 0.220};  // Palacin Eq. 16
  robot.bounds.radius_m = {0.138, 0.158};
  robot.bounds.angle_offset_rad = {-2.0 * M_PI / 180.0, 2.0 * M_PI / 180.0};
  return robot;
}

std::vector<double> ParameterVector(const omni3::Parameters& p) {
  const auto a = p.ToArray();
  return {a.begin(), a.end()};
}

}  // namespace sim

ModelExtras Omni3Extras() {
  ModelExtras extras;
  // Wheels tangential by construction: the replay sets its own R_, r_, delta_ by name.
  extras.controllers = {OmniWheelController(OmniWheelReplay::kOwnModelByName)};
  extras.display = &InverseKinematicMatrixColumns;
  extras.scenario.trajectories = &FlowerScenario;
  extras.scenario.default_truth = [](const Robot& /*nominal*/) {
    return sim::ParameterVector(sim::PalacinTable5Parameters());
  };
  extras.scenario.stepped_physics = true;
  return extras;
}

}  // namespace fitcal
