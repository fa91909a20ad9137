#pragma once
// Palacin et al. 2022's flower (models/omni/) on the generic simulator (model_simulator.h):
// APR-02, a three-wheeled omni robot (models/omni3), drives the 36 trajectories of Table A1
// (flower_trajectories.h) commanded with its nominal parameters (Eq. 15) while it moves with the
// true ones (Table 5 by default), under the flower's time-stepped physics (SteppedOptions:
// controller lag, slip, jittered encoders, irregular ground truth). The defaults are the ones
// `fitcal simulate --out data/flower --robot data/robots/apr02.yaml --repetitions 10 --seed 1`
// used to write the shipped data/flower; its files are reproduced byte for byte
// (simulate_command_test).
//
// Defaults (docs/simulate.md): encoders every 10 ms +- 0.5 ms counting 4096 ticks per
// revolution; controller lag tau = 0.12 s, 0.5 s at rest before and 1.5 s after; slip sigma
// 0.3 %, 0.5 s correlation; 0.5 ms substeps; ground truth every 200-300 ms with 2 mm per axis and
// 0.2 deg; a random start pose (+-2 m, any heading).

#include <vector>

#include "models/omni3/omni3_robot.h"
#include "models/omni3/omni3_robot_model.h"
#include "models/omni/flower_trajectories.h"
#include "sim/model_simulator.h"

namespace fitcal::sim {

// Palacin Table 5: the STE-GA5 calibrated parameters of APR-02, the default simulated truth.
omni3::Parameters PalacinTable5Parameters();
// Palacin Eq. 15: the nominal parameters.
omni3::Parameters PalacinNominalParameters();
// APR-02 as data/robots/apr02.yaml describes it: Eq. 15 nominal, Eq. 16 bounds.
Omni3Robot PalacinApr02Robot();
// The nine parameters in the seam's order (Eq. 15: R_i, r_i, delta_i).
std::vector<double> ParameterVector(const omni3::Parameters& p);

// The flower's options (header) with the robot the controller commands.
SimulationOptions FlowerSimulationOptions(const std::vector<double>& commanded_parameters);

// A whole flower simulation: the nominal robot (it commands; fits start from it), the truth,
// the commands, the repetitions and the options. Change any field before SimulateFlower.
struct FlowerSimulation {
  RobotModelPtr model;
  std::vector<double> true_parameters;
  std::vector<MotionCommand> trajectories = FlowerTrajectories();
  int repetitions = 10;
  SimulationOptions options;
};

// APR-02 (Eq. 15 nominal) with the Table 5 truth and the defaults of the header.
FlowerSimulation PalacinFlower();
// The same without noise: no slip, no ground-truth noise, no jitter and near-ideal encoders
// (2^22 counts/rev), one repetition. What then remains between the simulator and Eq. 4 is the
// replay's discretisation.
FlowerSimulation NoiseFreePalacinFlower();

// All trajectories x repetitions, ordered by repetition then trajectory; ids "<label>-rep<NN>".
std::vector<ModelSimulatedRun> SimulateFlower(const FlowerSimulation& flower);
// The same, only the logs (what most callers want).
std::vector<RunLog> SimulateFlowerLogs(const FlowerSimulation& flower);

}  // namespace fitcal::sim
