#include "sim/flower_scenario.h"

#include <cmath>
#include <stdexcept>

namespace fitcal::sim {

namespace {

omni3::Parameters Make(double r_a, double r_b, double r_c, double wr_a, double wr_b, double wr_c,
                       double d_a_deg, double d_b_deg, double d_c_deg) {
  omni3::Parameters p;
  p.distance_m = {r_a, r_b, r_c};
  p.radius_m = {wr_a, wr_b, wr_c};
  p.angle_rad = {d_a_deg * M_PI / 180.0, d_b_deg * M_PI / 180.0, d_c_deg * M_PI / 180.0};
  return p;
}

}  // namespace

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

SimulationOptions FlowerSimulationOptions(const std::vector<double>& commanded_parameters) {
  SimulationOptions o;
  o.encoder_period_s = 0.010;  // APR-02: 10 ms PID period
  o.rest_before_s = 0.5;
  o.rest_after_s = 1.5;
  o.ticks_per_rev.assign(omni3::kNumWheels, 4096.0);
  o.gt_position_sigma_m = 0.002;
  o.gt_heading_sigma_rad = 0.2 * M_PI / 180.0;
  o.start_position_range_m = 2.0;
  o.random_start_heading = true;
  o.stepped.emplace();
  o.stepped->commanded_parameters = commanded_parameters;
  return o;
}

FlowerSimulation PalacinFlower() {
  FlowerSimulation f;
  f.model = Omni3ModelOf(PalacinApr02Robot());
  f.true_parameters = ParameterVector(PalacinTable5Parameters());
  f.options = FlowerSimulationOptions(f.model->robot().nominal);
  return f;
}

FlowerSimulation NoiseFreePalacinFlower() {
  FlowerSimulation f = PalacinFlower();
  f.repetitions = 1;
  f.options.gt_position_sigma_m = 0.0;
  f.options.gt_heading_sigma_rad = 0.0;
  f.options.ticks_per_rev.assign(omni3::kNumWheels, static_cast<double>(1 << 22));
  f.options.stepped->slip.sigma = 0.0;
  f.options.stepped->encoder.jitter_s = 0.0;
  return f;
}

std::vector<ModelSimulatedRun> SimulateFlower(const FlowerSimulation& flower) {
  return SimulateRuns(*flower.model, flower.true_parameters,
                      FlowerSpecs(flower.trajectories, flower.repetitions), flower.options);
}

std::vector<RunLog> SimulateFlowerLogs(const FlowerSimulation& flower) {
  std::vector<RunLog> logs;
  for (ModelSimulatedRun& run : SimulateFlower(flower)) logs.push_back(std::move(run.log));
  return logs;
}

}  // namespace fitcal::sim
