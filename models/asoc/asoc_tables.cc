#include "models/asoc/asoc_tables.h"

#include <cmath>
#include <random>
#include <stdexcept>

#include "models/asoc/asoc_extras.h"
#include "odometry/parallel_for.h"

namespace fitcal::asoc {

namespace {

std::vector<double> Parameters(const Vehicle& v) {
  const auto p = v.ToArray();
  return {p.begin(), p.end()};
}

// Table I's errors of one estimate: mean |relative error| of r_c, r_w, d, mean |error| of beta.
void AddParameterErrors(const Vehicle& truth, const Vehicle& estimate, double* out) {
  for (int i = 0; i < kNumCastors; ++i) {
    const CastorParameters& t = truth.castors[i];
    const CastorParameters& e = estimate.castors[i];
    out[0] += std::abs(e.offset_m / t.offset_m - 1.0) / 3.0;
    for (int k = 0; k < 2; ++k) {
      out[1] += std::abs(e.wheel_radius_m[k] / t.wheel_radius_m[k] - 1.0) / 6.0;
      out[2] += std::abs(e.wheel_offset_m[k] / t.wheel_offset_m[k] - 1.0) / 6.0;
    }
    out[3] += std::abs(WrapAngle(e.encoder_bias_rad - t.encoder_bias_rad)) / 3.0;
  }
}

}  // namespace

double UmbmarkEmax(const RobotModelInterface& odometry, const std::vector<double>& p,
                   const std::vector<RunLog>& runs) {
  double sum[2][2] = {{0.0, 0.0}, {0.0, 0.0}};
  int count[2] = {0, 0};
  for (const RunLog& run : runs) {
    const int dir = run.trajectory == "umbmark_cw" ? 0 : run.trajectory == "umbmark_ccw" ? 1 : -1;
    if (dir < 0) continue;
    const Pose2d start = run.start_pose.value_or(run.ground_truth.world_T_robot.front());
    const Pose2d est = odometry.ReplayFinalPose(p.data(), run.encoders.samples, start);
    const Pose2d& truth = run.ground_truth.world_T_robot.back();
    sum[dir][0] += est.x - truth.x;
    sum[dir][1] += est.y - truth.y;
    ++count[dir];
  }
  if (count[0] == 0 || count[1] == 0) {
    throw std::invalid_argument("UMBmark needs umbmark_cw and umbmark_ccw runs");
  }
  return std::max(std::hypot(sum[0][0], sum[0][1]) / count[0],
                  std::hypot(sum[1][0], sum[1][1]) / count[1]);
}

DoebblerTables SimulateDoebblerTables(const AsocModel& nominal_model, int sets,
                                      std::uint64_t seed, const SimulateFn& simulate,
                                      int threads) {
  const Vehicle nominal = nominal_model.asoc().nominal;
  const double resolution = nominal_model.asoc().pivot_resolution_rad;
  // Doebbler Table II's algorithms: IPEC-1, CAST-1, CAST-0 (castor 1 left out, or none).
  std::vector<RobotModelPtr> algorithms;
  for (const char* name : {"IPEC-1", "CAST-1", "CAST-0"}) {
    AsocOdometryOptions o;
    AsocOdometryOptions::Parse(name, &o);
    algorithms.push_back(nominal_model.WithOdometry(o));
  }
  const std::vector<sim::TrajectorySpec> holds = HoldTrajectories(nominal);
  const std::vector<sim::TrajectorySpec> umbmark = UmbmarkTrajectories(5, 1);
  const std::size_t n = static_cast<std::size_t>(sets);
  std::vector<DoebblerTables> results(n);
  ParallelFor(n, threads, [&](std::size_t s) {
    const std::uint64_t set_seed = SplitMix(seed ^ SplitMix(s));
    std::mt19937_64 rng(set_seed);
    DoebblerTables& r = results[s];
    // Table I: a random parameter set through the calibration.
    const Vehicle truth = DrawVehicle(nominal, ParameterSpread{}, rng);
    GeometricResult cal =
        CalibrateGeometric(simulate(Parameters(truth), holds, set_seed), nominal, resolution);
    AddParameterErrors(truth, nominal, r.param[0]);
    AddParameterErrors(truth, cal.estimate, r.param[1]);
    // Table II: beta = 0 in the truth (Doebbler Sec. IV-B), UMBmark 5 x CW and CCW.
    ParameterSpread spread;
    spread.bias_range_rad = 0.0;
    const Vehicle truth2 = DrawVehicle(nominal, spread, rng);
    cal = CalibrateGeometric(simulate(Parameters(truth2), holds, set_seed + 1), nominal,
                             resolution);
    const std::vector<RunLog> runs = simulate(Parameters(truth2), umbmark, set_seed + 2);
    for (std::size_t a = 0; a < algorithms.size(); ++a) {
      r.emax[0][a] = UmbmarkEmax(*algorithms[a], Parameters(nominal), runs);
      r.emax[1][a] = UmbmarkEmax(*algorithms[a], Parameters(cal.estimate), runs);
    }
  });
  DoebblerTables mean;
  for (const DoebblerTables& r : results) {
    for (int w = 0; w < 2; ++w) {
      for (int k = 0; k < 4; ++k) mean.param[w][k] += r.param[w][k] / n;
      for (int a = 0; a < 3; ++a) mean.emax[w][a] += r.emax[w][a] / n;
    }
  }
  return mean;
}

}  // namespace fitcal::asoc
