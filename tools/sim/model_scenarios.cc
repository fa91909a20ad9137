#include "tools/sim/model_scenarios.h"

#include <stdexcept>

#include "tools/sim/diff_drive_trajectories.h"
#include "tools/sim/omni_trajectories.h"
#include "tools/sim/tricycle_trajectories.h"

namespace fitcal::sim {

namespace {

std::vector<TrajectorySpec> DiffDriveScenario(const Robot& /*robot*/, int repetitions) {
  DiffDriveTrajectoryOptions shapes;
  shapes.circle_laps = 1.25;  // open arcs: the scale (header)
  return DiffDriveCalibrationTrajectories(repetitions, shapes);
}

std::vector<TrajectorySpec> TricycleScenario(const Robot& robot, int repetitions) {
  TricycleTrajectoryOptions shapes;
  // Circles are commanded by steering angle through the nominal wheelbase (the robot's belief).
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (robot.parameters[k].group == "wheelbase_m") shapes.wheelbase_m = robot.nominal[k];
  }
  shapes.repetitions = repetitions;
  return TricycleTrajectories(shapes);
}

std::vector<TrajectorySpec> OmniScenario(const Robot& /*robot*/, int repetitions) {
  OmniTrajectoryOptions shapes;
  shapes.spin_angle_rad = 2.0 * M_PI;
  return OmniFlowerTrajectories(repetitions, shapes);
}

// One line per model with calibration trajectories.
// One line per model with calibration trajectories, and how far its default true robot is from
// the nominal one (DefaultTrueParameters, as a fraction of the way to the bounds).
constexpr struct {
  const char* model;
  std::vector<TrajectorySpec> (*trajectories)(const Robot&, int);
  double truth_fraction;
} kScenarios[] = {
    {"diff_drive", &DiffDriveScenario, 0.025},
    {"omni", &OmniScenario, 0.25},
    {"tricycle", &TricycleScenario, 0.25},
};

}  // namespace

std::string ScenarioModelNames() {
  std::string out;
  for (const auto& s : kScenarios) out += (out.empty() ? "" : ", ") + std::string(s.model);
  return out;
}

ModelScenario MakeModelScenario(const RobotModelInterface& model, const ScenarioNoise& noise) {
  const Robot& robot = model.robot();
  if (noise.repetitions < 1) throw std::invalid_argument("--repetitions must be at least 1");
  for (const auto& s : kScenarios) {
    if (robot.model != s.model) continue;
    ModelScenario out;
    out.trajectories = s.trajectories(robot, noise.repetitions);
    SimulationOptions& o = out.options;
    o.encoder_period_s = noise.encoder_period_s;
    o.ground_truth_period_s = noise.ground_truth_period_s;
    o.ticks_per_rev.assign(robot.channels.size(), 0.0);
    for (std::size_t i = 0; i < robot.channels.size(); ++i) {
      if (robot.channels[i].kind == ChannelKind::kWheelRate)
        o.ticks_per_rev[i] = noise.ticks_per_rev;
    }
    o.wheel_rate_sigma_rad_s = noise.wheel_rate_sigma_rad_s;
    o.angle_sigma_rad = noise.angle_sigma_rad;
    o.gt_position_sigma_m = noise.gt_position_sigma_m;
    o.gt_heading_sigma_rad = noise.gt_heading_sigma_rad;
    o.start_position_range_m = noise.start_position_range_m;
    o.random_start_heading = true;
    o.seed = noise.seed;
    return out;
  }
  throw std::invalid_argument("no calibration trajectories for model '" + robot.model +
                              "' (simulate --model takes " + ScenarioModelNames() +
                              "; omni3 without --model)");
}

std::vector<double> DefaultTrueParameters(const Robot& robot) {
  double fraction = 0.25;
  for (const auto& s : kScenarios) {
    if (robot.model == s.model) fraction = s.truth_fraction;
  }
  std::vector<double> p = robot.nominal;
  int moved = 0;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (robot.IsHeld(k)) continue;
    const double bound = moved % 2 == 0 ? robot.bounds[k].hi : robot.bounds[k].lo;
    p[k] += fraction * (bound - robot.nominal[k]);
    ++moved;
  }
  return p;
}

}  // namespace fitcal::sim
