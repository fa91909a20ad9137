#pragma once
// The calibration data set `fitcal simulate --model <name>` writes for a robot model on the seam
// (docs/simulate.md: each model's trajectories and the noise defaults): which trajectories each
// model drives, how far the simulated "true" robot is from the nominal one, and how the runs are
// recorded, for the generic simulator (model_simulator.h). Each model registers its trajectories,
// truth and recorder from its own folder (ModelExtras::scenario, models/model_extras.h; asoc the
// 20 Hz prototype of Doebbler et al.); this file finds them through the registry and replaces the
// recorder's values `simulate` is given (ScenarioNoise, scenario_noise.h). omni3 runs Palacin's
// flower under the stepped physics, its encoders written as a recorder writes them: data/flower's
// bytes.
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
  int repetitions = 0;  // --repetitions, or the scenario's default
  std::string repetition_unit;  // SimulationScenario::repetition_unit
  std::vector<TrajectorySpec> trajectories;  // ordered by repetition, then trajectory
  SimulationOptions options;
  EncoderCsvDigits digits = EncoderCsvDigits::kRoundTrip;
};

// The scenario for the model's robot, recorded as its recorder says with the values `noise`
// replaces; std::invalid_argument naming the models that have one when the robot's model has none;
// UsageError for no run at all, for slip or injected effects outside the stepped physics, for the
// per-sample wheel slip inside it and for an effect the robot's channels cannot show.
ModelScenario MakeModelScenario(const RobotModelInterface& model, const std::vector<double>& truth,
                                const ScenarioNoise& noise);

// The simulator's options for runs of `model` recorded as `recorder` says (counts on the wheel
// channels only), with the model's channel dynamics.
SimulationOptions RecordedAs(const RobotModelInterface& model, const ScenarioRecorder& recorder,
                             std::uint64_t seed);

// The simulator of a published experiment (ModelExtras::paper_tables): runs of the model with its
// own channel dynamics, recorded as `recorder` says; `model` must outlive the function.
SimulateFn ScenarioSimulator(const RobotModelInterface& model, const ScenarioRecorder& recorder);

// `fitcal paper-tables --model <name>`: the tables the model reproduces (ModelExtras::
// paper_tables) on its registry example robot, with request.wheel_slip_sigma as the recorder's
// relative wheel noise, as the model prints them. UsageError naming the models that reproduce a
// table when `model` does not.
std::string ReproducePaperTables(const std::string& model, const PaperTablesRequest& request);

// The default true robot of the header: nominal moved a fraction of the way to a bound, or the
// model's own (drawn from `seed` where the model draws it).
std::vector<double> DefaultTrueParameters(const Robot& robot, std::uint64_t seed = 1);

}  // namespace fitcal::sim
