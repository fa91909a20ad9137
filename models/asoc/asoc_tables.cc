#include "models/asoc/asoc_tables.h"

#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>

#include "models/asoc/asoc_extras.h"
#include "odometry/parallel_for.h"
#include "odometry/text_format.h"

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

// Means over `sets` random parameter sets (set s draws from std::mt19937_64 seeded by
// SplitMix(seed ^ SplitMix(s)), odometry/split_mix.h): Table I, the mean absolute relative error
// [uncalibrated, calibrated] of r_c, r_w, d and the absolute error of beta (rad); Table II,
// UMBmark E_max (m) [uncalibrated, calibrated] of IPEC-1, CAST-1 and CAST-0 on a truth with
// beta = 0 (Doebbler Sec. IV-B), 5 circuits each way.
struct DoebblerTables {
  double param[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
  double emax[2][3] = {{0, 0, 0}, {0, 0, 0}};
};

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

// Table I: the mean absolute errors against the paper's (Doebbler Table I).
std::string TableOne(const DoebblerTables& mean) {
  std::string out = "Table I: mean absolute parameter error\n\n";
  out += "| parameter | uncalibrated | calibrated | paper uncal. | paper cal. |\n";
  out += "|---|---|---|---|---|\n";
  const char* names[4] = {"r_c", "r_w", "d", "beta"};
  const char* paper[4][2] = {
      {"0.21%", "0.09%"}, {"2.07%", "0.04%"}, {"0.89%", "0.04%"}, {"7.98 deg", "0.01 deg"}};
  for (int k = 0; k < 4; ++k) {
    out += k < 3 ? StrFormat("| %s | %.3f%% | %.3f%% | %s | %s |\n", names[k],
                             100 * mean.param[0][k], 100 * mean.param[1][k], paper[k][0],
                             paper[k][1])
                 : StrFormat("| %s | %.3f deg | %.4f deg | %s | %s |\n", names[k],
                             RadToDeg(mean.param[0][k]), RadToDeg(mean.param[1][k]), paper[k][0],
                             paper[k][1]);
  }
  return out;
}

// Table II: UMBmark E_max of the three algorithms against the paper's (Doebbler Table II; the
// percentage of the 6 m circuit), and the ratios the paper draws its conclusions from.
std::string TableTwo(const DoebblerTables& mean) {
  std::string out = "\nTable II: UMBmark E_max (1.5 m square, 5 x CW and CCW, 6 m per circuit)\n\n";
  out += "| algorithm | uncalibrated | calibrated | ratio | paper uncal. | paper cal. |\n";
  out += "|---|---|---|---|---|---|\n";
  const char* algorithm[3] = {"IPEC-1", "CAST-1", "CAST-0"};
  const char* paper[3][2] = {{"394.6 mm 6.89%", "71.7 mm 1.25%"},
                             {"394.1 mm 6.88%", "71.6 mm 1.25%"},
                             {"311.0 mm 5.43%", "39.0 mm 0.68%"}};
  for (int a = 0; a < 3; ++a) {
    out += StrFormat("| %s | %.1f mm %.2f%% | %.2f mm %.3f%% | %.0fx | %s | %s |\n", algorithm[a],
                     1000 * mean.emax[0][a], 100 * mean.emax[0][a] / 6.0, 1000 * mean.emax[1][a],
                     100 * mean.emax[1][a] / 6.0, mean.emax[0][a] / mean.emax[1][a], paper[a][0],
                     paper[a][1]);
  }
  return out + StrFormat(
                   "\nratios: CAST-0 / two-castor uncalibrated %.3f (paper 0.79), calibrated %.3f "
                   "(paper 0.54); IPEC-1 / CAST-1 uncalibrated %.4f (paper 1.0013)\n",
                   mean.emax[0][2] / mean.emax[0][1], mean.emax[1][2] / mean.emax[1][1],
                   mean.emax[0][0] / mean.emax[0][1]);
}

std::string ReproduceDoebblerTables(const RobotModelInterface& nominal,
                                    const PaperTablesRequest& request,
                                    const SimulateFn& simulate) {
  const auto* asoc = dynamic_cast<const AsocModel*>(&nominal);
  if (asoc == nullptr) throw std::invalid_argument("not an asoc robot: " + nominal.robot().model);
  const DoebblerTables mean = SimulateDoebblerTables(*asoc, request.sets, request.seed, simulate,
                                                     request.threads);
  return StrFormat("Doebbler et al. Tables I and II, %d random parameter sets (seed %llu, wheel "
                   "slip sigma %g per 20 Hz sample)\n\n",
                   request.sets, static_cast<unsigned long long>(request.seed),
                   request.wheel_slip_sigma) +
         TableOne(mean) + TableTwo(mean);
}

}  // namespace

PaperTables DoebblerPaperTables() {
  PaperTables tables;
  tables.recorder = PrototypeRecorder();
  tables.recorder.random_start_heading = false;
  tables.recorder.substep_s = kPrototypeSamplePeriodS / 10.0;
  tables.reproduce = &ReproduceDoebblerTables;
  return tables;
}

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

}  // namespace fitcal::asoc
