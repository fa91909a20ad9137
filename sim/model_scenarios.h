#pragma once
// The calibration data set `fitcal simulate --model <name>` writes for a robot model on the seam
// (README "Simulator"): which trajectories each model drives, how far the simulated "true" robot
// is from the nominal one, and the noise, for the generic simulator (model_simulator.h).
//
// Each model registers its trajectories and truth fraction from its own folder
// (ModelExtras::scenario, models/model_extras.h); this file finds them through the registry.
// Trajectories, per model (labels as the data set's `trajectory`):
//   diff_drive  Borenstein & Feng's UMBmark squares, clockwise and counter-clockwise, and circles
//               of radius 0.5 and 1.0 m both ways (models/diff_drive/diff_drive_trajectories.h).
//               The circles are 1.25 laps: a closed path ends where it started for any common
//               scale of the radii and the separation, so only open arcs tell the scale.
//   tricycle    circles at steering angles 10, 20, 30, 45 deg both ways (1.25 turns) and squares
//               with in-place turns both ways, each with an extra side
//               (models/tricycle/tricycle_trajectories.h, "open on purpose").
//   omni        Palacin's flower generalised to any wheel count (models/omni/omni_trajectories.h):
//               R1..R12, G1..G12, B1..B12 (v = 0.35 m/s, 1 m, |omega| 0.35 rad/s) and one turn
//               on the spot each way (S-ccw, S-cw), which excites the yaw alone.
//   omni3       Palacin's flower, Table A1 as printed (models/omni3/omni3_extras.h), under the
//               stepped physics (SteppedOptions in model_simulator.h: the controller lag's 1.5 s
//               to settle after the last command, slip, jittered encoders, irregular ground
//               truth), its encoders written as a recorder writes them: data/flower's bytes.
//
// The true robot (DefaultTrueParameters): every free parameter moved from its nominal value a
// fraction f of the way to its upper bound (1st, 3rd, ... free parameter) or to its lower bound
// (2nd, 4th, ...); parameters the model holds (gauge) stay nominal, since no data can move them;
// a model with a published truth registers it instead (omni3: Palacin Table 5).
// f = 1/4 for tricycle and omni; 1/40 for diff_drive, whose example robot then has E_d = 1.0048
// and E_b = 1.0025 (UMBmark-sized: Borenstein & Feng's corrections are of this order, and larger
// ones leave the nominal odometry of a 1 m square more than a quarter side from closing, which
// UMBmark refuses).
//
// Noise (ScenarioNoise in scenario_noise.h; defaults as the omni3 simulator's where they share a
// concept):
// encoders every 10 ms, wheel angles counted with 4096 ticks per revolution, a white noise of
// 0.02 rad/s on each interval's mean wheel rate (a random walk of the wheel angle), angle
// channels (a steering angle) read with 0.1 deg of white noise; ground truth every 0.2 s with
// 2 mm per axis and 0.2 deg; a random start pose (+-2 m, any heading) that the data set does not
// record (the fit takes it from the noisy ground truth); 0.4 s raised-cosine ramps between
// segments, 0.5 s at rest before and after.

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
