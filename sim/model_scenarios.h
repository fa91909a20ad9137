#pragma once
// The calibration data set `fitcal simulate --model <name>` writes for a robot model on the seam
// (docs/simulate.md: each model's trajectories and the noise defaults, ScenarioNoise in
// scenario_noise.h): which trajectories each model drives, how far the simulated "true" robot is
// from the nominal one, and the noise, for the generic simulator (model_simulator.h). Each model
// registers its trajectories and truth fraction from its own folder (ModelExtras::scenario,
// models/model_extras.h); this file finds them through the registry. omni3 runs Palacin's flower
// under the stepped physics, its encoders written as a recorder writes them: data/flower's bytes.
//
// The true robot (DefaultTrueParameters): every free parameter moved from its nominal value a
// fraction f of the way to its upper bound (1st, 3rd, ... free parameter) or to its lower bound
// (2nd, 4th, ...); parameters the model holds (gauge) stay nominal, since no data can move them;
// a model with a published truth registers it instead (omni3: Palacin Table 5).
// f = 1/4 for tricycle and omni; 1/40 for diff_drive, whose example robot then has E_d = 1.0048
// and E_b = 1.0025 (UMBmark-sized: Borenstein & Feng's corrections are of this order, and larger
// ones leave the nominal odometry of a 1 m square more than a quarter side from closing, which
// UMBmark refuses).

#include <string>
#include <vector>

#include "models/model_interface.h"
#include "sim/model_simulator.h"
#include "sim/scenario_noise.h"

namespace fitcal::sim {

struct ModelScenario {
  std::vector<TrajectorySpec> trajectories;  // ordered by repetition, then trajectory
  SimulationOptions options;
  EncoderCsvDigits digits = EncoderCsvDigits::kRoundTrip;
};

// The scenario for the model's robot; std::invalid_argument naming the models that have one when
// the robot's model has none; UsageError for slip or injected effects outside the stepped physics
// and for an effect the robot's channels cannot show.
ModelScenario MakeModelScenario(const RobotModelInterface& model, const std::vector<double>& truth,
                                const ScenarioNoise& noise);

// The default true robot of the header: nominal moved a fraction of the way to a bound, or the
// model's own (drawn from `seed` where the model draws it).
std::vector<double> DefaultTrueParameters(const Robot& robot, std::uint64_t seed = 1);

}  // namespace fitcal::sim
