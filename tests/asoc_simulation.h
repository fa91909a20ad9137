#pragma once
// ASOC runs for the tests on the one simulator (sim/model_simulator.h) with the castor dynamics
// the asoc model registers (models/asoc/asoc_extras.h), the prototype's encoders as
// `paper-tables --model asoc` records them: 20 Hz, wheels counted in 0.3 deg, pivots read in
// 0.07 deg, noise-free ground truth at every encoder time, each run from the origin heading +x.

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <vector>

#include "models/asoc/asoc_extras.h"
#include "models/asoc/asoc_robot_model.h"
#include "models/model_registry.h"
#include "sim/model_scenarios.h"
#include "sim/model_simulator.h"

namespace fitcal::asoc {

// The simulated prototype (kAsocExampleYaml): pivots on a 0.30 m circle, r_c 0.08 m, r_w 0.04 m,
// d 0.06 m; Doebbler do not print their dimensions.
inline Vehicle PrototypeVehicle() {
  Vehicle v;
  for (int i = 0; i < kNumCastors; ++i) {
    v.pivots[i] = {0.30, 2.0 * M_PI * i / 3.0};  // phi_1 = 0 (Doebbler Sec. II-C)
    v.castors[i].offset_m = 0.08;
    v.castors[i].wheel_radius_m = {0.04, 0.04};
    v.castors[i].wheel_offset_m = {0.06, 0.06};
  }
  return v;
}

inline const AsocModel& ExampleAsocModel() {
  static const RobotModelPtr model = ReadRobotModel(YAML::Load(kAsocExampleYaml), "asoc example");
  return dynamic_cast<const AsocModel&>(*model);
}

// The prototype's recorder as the asoc model registers it for Doebbler's tables
// (ModelExtras::paper_tables.recorder, models/asoc/asoc_tables.cc), with the wheel slip and the
// wheels' counts given. pivot_quantum_rad < 0: the example robot's pivot_resolution_deg;
// wheel_ticks_per_rev 0: exact.
inline sim::SimulationOptions PrototypeSimulation(std::uint64_t seed, double wheel_slip_sigma,
                                                  double pivot_quantum_rad = -1.0,
                                                  double wheel_ticks_per_rev =
                                                      kPrototypeWheelTicksPerRev) {
  ScenarioRecorder recorder = ExtrasOf("asoc").paper_tables.recorder;
  recorder.wheel_relative_sigma = wheel_slip_sigma;
  recorder.ticks_per_rev = wheel_ticks_per_rev;
  sim::SimulationOptions o = sim::RecordedAs(ExampleAsocModel(), recorder, seed);
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
