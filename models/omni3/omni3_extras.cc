#include "models/omni3/omni3_extras.h"

#include <cmath>

#include "models/omni/flower_trajectories.h"
#include "models/omni/omni_extras.h"
#include "models/omni3/omni3_parameters.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

std::string MatrixText(const Eigen::Matrix3d& m) {
  std::string out = "[";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      out += (std::isnan(m(r, c)) ? "-" : StrFormat("%.4f", m(r, c))) + (c < 2 ? " " : "");
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
std::vector<sim::TrajectorySpec> FlowerScenario(const RobotModelInterface& /*nominal*/,
                                                const std::vector<double>& /*truth*/,
                                                int repetitions) {
  return sim::FlowerSpecs(sim::FlowerTrajectories(), repetitions);
}

}  // namespace

namespace sim {

omni3::Parameters PalacinTable5Parameters() {
  omni3::Parameters p;
  p.distance_m = {0.218643, 0.215735, 0.216287};
  p.radius_m = {0.155068, 0.151534, 0.152728};
  p.angle_rad = {59.7397 * M_PI / 180.0, 179.6820 * M_PI / 180.0, 301.5735 * M_PI / 180.0};
  return p;
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
  extras.scenario.default_truth = [](const Robot& /*nominal*/, std::uint64_t /*seed*/) {
    return sim::ParameterVector(sim::PalacinTable5Parameters());
  };
  extras.scenario.stepped_physics = true;
  return extras;
}

}  // namespace fitcal
