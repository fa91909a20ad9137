#include "sim/asoc_scenarios.h"

#include <cmath>
#include <filesystem>
#include <random>

#include "io/atomic_file.h"
#include "io/dataset.h"
#include "models/asoc/asoc_geometric.h"
#include "odometry/parallel_for.h"
#include "sim/model_dataset.h"
#include "sim/stepped_run.h"

namespace fitcal::sim {

namespace {

// The simulated pivot encoders' step is stated, as a user states their encoders'.
io::AsocRobot RobotFromVehicle(const std::string& name, const asoc::Vehicle& v) {
  io::AsocRobot robot;
  robot.name = name;
  robot.pivot_resolution_rad = AsocSimulationOptions{}.pivot_quantum_rad;
  robot.pivot_distance_m = v.PivotDistance(0, 1);
  robot.nominal = v;
  return robot;
}

// UMBmark circuits, 5 CW and 5 CCW, as repetitions 6-10 so that the default --train-reps 1-5
// validates on them. Each repetition drives at its own speed (0.30, 0.306, ... m/s): noise-free
// identical circuits would be one recording copied, which the loader refuses (io/dataset.cc).
std::vector<asoc::RunLog> UmbmarkCircuits(const asoc::Vehicle& truth,
                                          const AsocSimulationOptions& options,
                                          std::mt19937_64& rng) {
  std::vector<asoc::RunLog> runs;
  for (int direction : {-1, +1}) {
    for (int rep = 6; rep <= 10; ++rep) {
      const double speed_m_s = 0.3 * (1.0 + 0.02 * (rep - 6));
      const std::vector<Segment> square = UmbmarkSquare(direction, 1.5, speed_m_s);
      asoc::RunLog run = SimulateAsocRun(
          truth, square, Pose2d{}, SteadyCastorAngles(truth, square.front()), options, rng);
      run.trajectory = direction < 0 ? "umbmark_cw" : "umbmark_ccw";
      run.repetition = rep;
      run.id = run.trajectory + "-rep" + std::to_string(rep);
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

}  // namespace

AsocSimulatedDataset SimulateAsocDataset(std::uint64_t seed, double wheel_slip_sigma,
                                         int excursions) {
  std::mt19937_64 rng(SplitMix(seed));
  const asoc::Vehicle nominal = AsocPrototypeVehicle();
  const asoc::Vehicle truth = DrawVehicle(nominal, ParameterSpread{}, rng);
  AsocSimulationOptions sim_options;
  sim_options.wheel_slip_sigma = wheel_slip_sigma;
  AsocSimulatedDataset out;
  out.runs = SimulateCalibrationManoeuvre(truth, sim_options, rng);
  for (asoc::RunLog& run : UmbmarkCircuits(truth, sim_options, rng))
    out.runs.push_back(std::move(run));
  for (int k = 1; k <= excursions; ++k) {
    asoc::RunLog run = SimulateRandomExcursion(truth, sim_options, rng);
    run.trajectory = "excursion";
    run.repetition = k;
    run.id = "excursion-rep" + std::to_string(k);
    out.runs.push_back(std::move(run));
  }
  out.nominal = RobotFromVehicle("asoc-prototype", nominal);
  out.truth = RobotFromVehicle("asoc-truth", truth);
  return out;
}

void WriteAsocDataset(const AsocSimulatedDataset& dataset, const std::string& directory) {
  namespace fs = std::filesystem;
  const fs::path out(directory);
  fs::create_directories(out / "runs");
  std::vector<io::DatasetEntry> entries;
  for (const asoc::RunLog& run : dataset.runs) {
    const std::string enc = "runs/" + run.id + "_encoders.csv";
    const std::string gt = "runs/" + run.id + "_ground_truth.csv";
    io::WriteFileAtomically((out / enc).string(), io::AsocEncoderCsv(run.encoders));
    io::WriteFileAtomically((out / gt).string(), io::GroundTruthCsv(run.ground_truth));
    entries.push_back({run.id, run.trajectory, run.repetition, enc, gt});
  }
  io::WriteFileAtomically((out / "robot.yaml").string(), io::AsocRobotYaml(dataset.nominal));
  io::WriteFileAtomically((out / "true_robot.yaml").string(), io::AsocRobotYaml(dataset.truth));
  io::WriteFileAtomically((out / "dataset.yaml").string(), io::DatasetYaml("robot.yaml", entries));
}

std::size_t WriteSimulatedAsocDataset(const std::string& out, bool force, std::uint64_t seed,
                                      double wheel_slip_sigma, int excursions) {
  std::size_t num_runs = 0;
  WriteDatasetDirectory(out, force, [&](const std::string& directory) {
    const AsocSimulatedDataset simulated =
        SimulateAsocDataset(seed, wheel_slip_sigma, excursions);
    WriteAsocDataset(simulated, directory);
    num_runs = simulated.runs.size();
  });
  return num_runs;
}

DoebblerTables SimulateDoebblerTables(int sets, std::uint64_t seed, double wheel_slip_sigma,
                                      int threads) {
  const asoc::Vehicle nominal = AsocPrototypeVehicle();
  AsocSimulationOptions sim_options;
  sim_options.wheel_slip_sigma = wheel_slip_sigma;
  const std::size_t n = static_cast<std::size_t>(sets);
  using SetResult = DoebblerTables;
  std::vector<SetResult> results(n);
  const int excluded[3] = {1, 1, 0};
  ParallelFor(n, threads, [&](std::size_t s) {
    std::mt19937_64 rng(SplitMix(seed ^ SplitMix(s)));
    SetResult& r = results[s];
    // Table I: 1000 random parameter sets through the calibration.
    const asoc::Vehicle truth = DrawVehicle(nominal, ParameterSpread{}, rng);
    asoc::GeometricResult cal = asoc::CalibrateGeometric(
        SimulateCalibrationManoeuvre(truth, sim_options, rng), nominal);
    for (int which = 0; which < 2; ++which) {
      const asoc::Vehicle& est = which == 0 ? nominal : cal.estimate;
      for (int i = 0; i < asoc::kNumCastors; ++i) {
        const asoc::CastorParameters& t = truth.castors[i];
        const asoc::CastorParameters& e = est.castors[i];
        r.param[which][0] += std::abs(e.offset_m / t.offset_m - 1.0) / 3.0;
        for (int k = 0; k < 2; ++k) {
          r.param[which][1] += std::abs(e.wheel_radius_m[k] / t.wheel_radius_m[k] - 1.0) / 6.0;
          r.param[which][2] += std::abs(e.wheel_offset_m[k] / t.wheel_offset_m[k] - 1.0) / 6.0;
        }
        r.param[which][3] += std::abs(WrapAngle(e.encoder_bias_rad - t.encoder_bias_rad)) / 3.0;
      }
    }
    // Table II: beta = 0 in the truth (Doebbler Sec. IV-B), UMBmark 5 x CW and CCW.
    ParameterSpread spread;
    spread.bias_range_rad = 0.0;
    const asoc::Vehicle truth2 = DrawVehicle(nominal, spread, rng);
    cal = asoc::CalibrateGeometric(SimulateCalibrationManoeuvre(truth2, sim_options, rng),
                                   nominal);
    const auto runs = SimulateUmbmark(truth2, sim_options, rng, 5);
    for (int a = 0; a < 3; ++a) {
      asoc::OdometryOptions o;
      o.castors = asoc::MaskExcluding(excluded[a]);
      if (a == 0) o.method = asoc::Method::kIpec;
      r.emax[0][a] = EvaluateUmbmark(runs, nominal, o).e_max_m;
      r.emax[1][a] = EvaluateUmbmark(runs, cal.estimate, o).e_max_m;
    }
  });
  SetResult mean;
  for (const SetResult& r : results) {
    for (int w = 0; w < 2; ++w) {
      for (int k = 0; k < 4; ++k) mean.param[w][k] += r.param[w][k] / n;
      for (int a = 0; a < 3; ++a) mean.emax[w][a] += r.emax[w][a] / n;
    }
  }
  return mean;
}

}  // namespace fitcal::sim
