#pragma once
// ASOC runs for the tests on the one simulator (sim/model_simulator.h) with the castor dynamics
// the asoc model registers (models/asoc/asoc_extras.h), the prototype's encoders as asoc-tables
// simulates them: 20 Hz, wheels counted in 0.3 deg, pivots read in 0.07 deg, noise-free ground
// truth at every encoder time, each run from the origin heading +x.

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <vector>

#include "models/asoc/asoc_extras.h"
#include "models/asoc/asoc_robot_model.h"
#include "models/model_registry.h"
#include "sim/model_simulator.h"

namespace fitcal::asoc {

inline const AsocModel& ExampleAsocModel() {
  static const RobotModelPtr model = ReadRobotModel(YAML::Load(kAsocExampleYaml), "asoc example");
  return dynamic_cast<const AsocModel&>(*model);
}

// pivot_quantum_rad < 0: the example robot's pivot_resolution_deg; wheel_ticks_per_rev 0: exact.
inline sim::SimulationOptions PrototypeSimulation(std::uint64_t seed, double wheel_slip_sigma,
                                                  double pivot_quantum_rad = -1.0,
                                                  double wheel_ticks_per_rev =
                                                      kPrototypeWheelTicksPerRev) {
  sim::SimulationOptions o;
  o.encoder_period_s = kPrototypeSamplePeriodS;
  o.ground_truth_period_s = kPrototypeSamplePeriodS;
  o.substep_s = kPrototypeSamplePeriodS / 10.0;
  o.ticks_per_rev.assign(kNumChannels, 0.0);
  for (int i = 0; i < kNumCastors; ++i) {
    o.ticks_per_rev[i * kChannelsPerCastor + kWheelAChannel] = wheel_ticks_per_rev;
    o.ticks_per_rev[i * kChannelsPerCastor + kWheelBChannel] = wheel_ticks_per_rev;
  }
  o.wheel_relative_sigma = wheel_slip_sigma;
  o.seed = seed;
  o.dynamics = ExtrasOf("asoc").scenario.dynamics;
  if (pivot_quantum_rad >= 0.0) {
    o.dynamics = [pivot_quantum_rad](const RobotModelInterface&, const std::vector<double>& p,
                                     const sim::TrajectorySpec& spec) {
      Vehicle truth = ExampleAsocModel().asoc().nominal;
      truth.SetFromArray(p.data());
      return MakeCastorDynamics(truth, SteadyCastorAngles(truth, spec.segments.front().twist),
                                pivot_quantum_rad);
    };
  }
  return o;
}

inline std::vector<RunLog> SimulateAsoc(const Vehicle& truth,
                                        const std::vector<sim::TrajectorySpec>& specs,
                                        const sim::SimulationOptions& options) {
  const auto p = truth.ToArray();
  std::vector<RunLog> logs;
  for (sim::ModelSimulatedRun& run :
       sim::SimulateRuns(ExampleAsocModel(), {p.begin(), p.end()}, specs, options)) {
    logs.push_back(std::move(run.log));
  }
  return logs;
}

inline std::vector<RunLog> SimulateAsoc(const Vehicle& truth,
                                        const std::vector<sim::TrajectorySpec>& specs,
                                        std::uint64_t seed = 1, double wheel_slip_sigma = 0.0) {
  return SimulateAsoc(truth, specs, PrototypeSimulation(seed, wheel_slip_sigma));
}
}  // namespace fitcal::asoc
