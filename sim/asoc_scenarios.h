#pragma once
// What `asoc-simulate` and `asoc-tables` simulate (cli/asoc_commands.h prints and writes it):
// the ASOC prototype's data set with a drawn true vehicle, and the Monte Carlo of Doebbler et al.
// Tables I and II. Both reproduce the commands' outputs bit for bit: one generator per seed
// (std::mt19937_64 seeded through SplitMix), drawn in the order written here.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "models/asoc/asoc_files.h"
#include "sim/asoc_simulator.h"

namespace fitcal::sim {

// The calibration holds (6 runs: each castor held, CW and CCW), 10 UMBmark circuits (5 CW, 5
// CCW, repetitions 6-10: the default --train-reps 1-5 validates on them) and `excursions` random
// excursions (repetitions 1..N), all driven by one true vehicle drawn about the prototype.
struct AsocSimulatedDataset {
  io::AsocRobot nominal;  // "asoc-prototype": the robot.yaml of the data set
  io::AsocRobot truth;    // "asoc-truth": what a calibration should find
  std::vector<asoc::RunLog> runs;
};
AsocSimulatedDataset SimulateAsocDataset(std::uint64_t seed, double wheel_slip_sigma,
                                         int excursions);

// Writes `dataset` into `directory` (a staged directory: the caller renames it over --out once
// complete): runs/<id>_encoders.csv and runs/<id>_ground_truth.csv per run, robot.yaml (the
// nominal), true_robot.yaml (the truth, named as every simulated data set names it) and
// dataset.yaml. ASOC's encoder files are the model's own format
// (models/asoc/asoc_files.h), so the command that calls this names no model.
void WriteAsocDataset(const AsocSimulatedDataset& dataset, const std::string& directory);

// What `asoc-simulate` calls once: SimulateAsocDataset written to `out` whole or not at all
// (sim/model_dataset.h WriteDatasetDirectory: UsageError for an `out` it may not write). Returns
// the number of runs.
std::size_t WriteSimulatedAsocDataset(const std::string& out, bool force, std::uint64_t seed,
                                      double wheel_slip_sigma, int excursions);

// Means over `sets` random parameter sets (each its own generator, seed ^ SplitMix(set)):
// Table I, the mean absolute relative error [uncalibrated, calibrated] of r_c, r_w, d and the
// absolute error of beta (rad); Table II, UMBmark E_max (m) [uncalibrated, calibrated] of IPEC-1,
// CAST-1 and CAST-0 on a truth with beta = 0 (Doebbler Sec. IV-B).
struct DoebblerTables {
  double param[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
  double emax[2][3] = {{0, 0, 0}, {0, 0, 0}};
};
DoebblerTables SimulateDoebblerTables(int sets, std::uint64_t seed, double wheel_slip_sigma,
                                      int threads);

}  // namespace fitcal::sim
