// Weights from the data (fit/noise_levels.h): a simulated differential drive whose odometry is
// exact (no encoder noise) and whose ground truth carries known white noise - sigma_xy per axis on
// the position, sigma_theta on the heading, every sample but the first (the start is exact, so each
// checkpoint from the start sees exactly that noise; the ground truth is sampled at the encoder
// times the checkpoints lie on). The track fit with weights estimated from the data recovers both
// levels within four standard errors derived from the number of checkpoints; `both` recovers the
// final poses' too. Through the command line: `fit` prints and records the estimate, and
// --heading-sigma-deg overrides it.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "fit/model_fit.h"
#include "fit/track_residual.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "tests/model_support.h"
#include "tests/test_files.h"
#include "models/diff_drive/diff_drive_trajectories.h"
#include "sim/model_simulator.h"

namespace fitcal {
namespace {

constexpr double kPositionSigmaM = 0.004;
constexpr double kHeadingSigmaRad = 0.02;  // 1.15 deg: far from 1 m : 1 rad's ratio
constexpr double kCommonScale = 1.02;      // true lengths / nominal

// wheel_rate_sigma: encoder noise (the data set on disk needs some: identical repetitions are
// refused as copied files); 0 keeps the odometry exact.
std::vector<sim::ModelSimulatedRun> Simulate(const RobotModelInterface& model, int repetitions,
                                             double wheel_rate_sigma_rad_s = 0.0) {
  sim::SimulationOptions o;
  o.wheel_rate_sigma_rad_s = wheel_rate_sigma_rad_s;
  o.encoder_period_s = 0.05;
  o.ground_truth_period_s = 0.05;  // a sample at every encoder time
  std::vector<double> truth = model.robot().nominal;
  for (double& v : truth) v *= kCommonScale;
  sim::DiffDriveTrajectoryOptions shapes;
  shapes.circle_laps = 1.25;  // open arcs: their tracks see every parameter
  std::vector<sim::ModelSimulatedRun> runs = sim::SimulateRuns(
      model, truth, sim::DiffDriveCalibrationTrajectories(repetitions, shapes), o);
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (sim::ModelSimulatedRun& run : runs) {
    std::vector<Pose2d>& poses = run.log.ground_truth.world_T_robot;
    for (std::size_t i = 1; i < poses.size(); ++i) {
      poses[i].x += kPositionSigmaM * normal(rng);
      poses[i].y += kPositionSigmaM * normal(rng);
      poses[i].theta += kHeadingSigmaRad * normal(rng);
    }
  }
  return runs;
}

// The simulated runs, aligned, and their track checkpoints, which point into `logs` and `runs`:
// built in place and never copied.
struct SimulatedTracks {
  SimulatedTracks(const RobotModelInterface& model, int repetitions) {
    for (const sim::ModelSimulatedRun& run : Simulate(model, repetitions)) logs.push_back(run.log);
    runs = AlignRuns(logs);
    std::vector<const GroundTruthTrack*> tracks;
    for (const RunLog& log : logs) tracks.push_back(&log.ground_truth);
    data = MakeTrackFitData(runs, tracks, ClockGrouping::kNone);
  }
  SimulatedTracks(const SimulatedTracks&) = delete;
  SimulatedTracks& operator=(const SimulatedTracks&) = delete;

  std::vector<RunLog> logs;
  std::vector<AlignedRun> runs;
  TrackFitData data;
};

// Relative standard error of a sigma estimated from runs whose checkpoints weigh 1/K each:
// each run adds mean_k(e^2) over its K checkpoints, a chi-square of `dimension` K degrees of
// freedom over K, variance 2 / (dimension K) relative; the N runs' mean has variance
// sum_i 2 / (dimension K_i) / N^2, and the sigma half its relative standard deviation.
double RelativeStandardError(const std::vector<int>& checkpoints, int dimension) {
  double variance = 0.0;
  for (int k : checkpoints) variance += 2.0 / (dimension * k);
  const double n = static_cast<double>(checkpoints.size());
  return 0.5 * std::sqrt(variance) / n;
}

TEST(NoiseLevels, TrackFitRecoversKnownPositionAndHeadingNoise) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  const SimulatedTracks simulated(*model, 3);
  const std::vector<AlignedRun>& runs = simulated.runs;
  const TrackFitData& data = simulated.data;
  std::vector<int> checkpoints;
  for (const TrackCheckpoints& t : data.runs)
    checkpoints.push_back(static_cast<int>(t.segments.size()));

  for (ResidualKind kind : {ResidualKind::kTrack, ResidualKind::kBoth}) {
    ModelFitOptions o;
    o.residuals = kind;
    o.track = &data;
    o.estimate_weights = true;
    o.ceres.num_threads = 1;
    const ModelFitResult fit = FitModel(runs, *model, o);
    ASSERT_TRUE(fit.usable) << ToString(kind) << ": " << fit.message;
    const NoiseLevels& levels = fit.noise_levels;
    ASSERT_TRUE(levels.estimated) << ToString(kind);
    EXPECT_TRUE(levels.settled) << NoiseLevelsText(levels);
    // The counts fit prints add up every round's solves: a Ceres iteration evaluates at least once
    // (iteration 0 the Jacobian, each step the residuals), so evaluations >= iterations. Before
    // the mend the evaluations were the last round's alone (the diff drive: 18 iterations, 9).
    EXPECT_GT(levels.iterations, 1) << NoiseLevelsText(levels);
    EXPECT_GE(fit.evaluations, fit.iterations) << ToString(kind);
    EXPECT_NEAR(levels.track_position_m / kPositionSigmaM, 1.0,
                4.0 * RelativeStandardError(checkpoints, 2))
        << ToString(kind) << ": " << NoiseLevelsText(levels);
    EXPECT_NEAR(levels.track_heading_rad / kHeadingSigmaRad, 1.0,
                4.0 * RelativeStandardError(checkpoints, 1))
        << ToString(kind) << ": " << NoiseLevelsText(levels);
    if (kind != ResidualKind::kBoth) continue;
    // One final pose per run: K = 1.
    const std::vector<int> ones(runs.size(), 1);
    EXPECT_NEAR(levels.final_position_m / kPositionSigmaM, 1.0,
                4.0 * RelativeStandardError(ones, 2))
        << NoiseLevelsText(levels);
    EXPECT_NEAR(levels.final_heading_rad / kHeadingSigmaRad, 1.0,
                4.0 * RelativeStandardError(ones, 1))
        << NoiseLevelsText(levels);
  }
}

// The sigmas are those of the objective the fit minimised. Estimated weights reach the track
// residuals as ModelFitOptions::track_weights while ceres.weights keeps 1 m : 1 rad; the sandwich
// covariance must weigh the track's errors as the fit did. The same weights given either way make
// the same objective, so the same parameters and the same covariance (to rounding: 1e-9
// relative). Before the mend the covariance's bread and meat were weighed 1 m : 1 rad whatever
// the fit had used: under the heading-heavy weighing below the sigmas came out 0.35-0.42 of the
// fit's own.
TEST(NoiseLevels, TrackSigmasAreOfTheWeightsTheFitUsed) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  const SimulatedTracks simulated(*model, 2);
  const std::vector<AlignedRun>& runs = simulated.runs;
  const TrackFitData& data = simulated.data;
  const ResidualWeights weights{1.0, kPositionSigmaM / 4.0};  // heading weighed 250x 1 m : 1 rad
  ModelFitOptions as_ceres;
  as_ceres.residuals = ResidualKind::kTrack;
  as_ceres.track = &data;
  as_ceres.ceres.num_threads = 1;
  as_ceres.ceres.weights = weights;
  ModelFitOptions as_track = as_ceres;
  as_track.ceres.weights = ResidualWeights{};
  as_track.track_weights = weights;
  const ModelFitResult a = FitModel(runs, *model, as_ceres);
  const ModelFitResult b = FitModel(runs, *model, as_track);
  ASSERT_TRUE(a.usable && a.has_covariance) << a.message;
  ASSERT_TRUE(b.usable && b.has_covariance) << b.message;
  for (std::size_t k = 0; k < a.parameters.size(); ++k) {
    EXPECT_NEAR(b.parameters[k], a.parameters[k], 1e-12 * std::abs(a.parameters[k])) << k;
    EXPECT_NEAR(b.sigma[k] / a.sigma[k], 1.0, 1e-9) << model->robot().parameters[k].name;
  }
}

// Through the command line: with --weights estimated the track fit prints its estimated weights and
// records them in the calibration's objective; a given sigma overrides the estimate and is recorded
// instead; by default (fixed) nothing is estimated.
TEST(NoiseLevels, FitCommandEstimatesWeightsUnlessASigmaIsGiven) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  testing::TempDir tmp;
  const std::string dir = tmp.Path("loops");
  sim::WriteSimulatedDataset(dir, FindModel("diff_drive")->example_yaml, Simulate(*model, 2, 0.01));
  const std::string fit = "fit --logs " + dir +
                          " --residuals track --threads 1 --train-reps 1-99 --weights estimated";

  const testing::FitcalRun estimated =
      testing::RunFitcal(tmp, fit + " --out " + tmp.Path("a.yaml"));
  ASSERT_EQ(estimated.exit_code, 0) << estimated.out << estimated.err;
  EXPECT_TRUE(testing::Has(estimated.out, "weights from the data (variance components"))
      << estimated.out;
  const std::string a = testing::ReadFileBytes(tmp.Path("a.yaml"));
  EXPECT_TRUE(testing::Has(a, "weights from the data: track position")) << a;

  const testing::FitcalRun given = testing::RunFitcal(
      tmp, fit + " --position-sigma-m 0.004 --heading-sigma-deg 1.15 --out " + tmp.Path("b.yaml"));
  ASSERT_EQ(given.exit_code, 0) << given.out << given.err;
  EXPECT_FALSE(testing::Has(given.out, "weights from the data")) << given.out;
  // The override said: an explicit --weights estimated was dropped without a word.
  EXPECT_TRUE(testing::Has(given.out + given.err, "note: --weights estimated not applied"))
      << given.out << given.err;
  const std::string b = testing::ReadFileBytes(tmp.Path("b.yaml"));
  EXPECT_TRUE(testing::Has(b, "sigma_xy 0.004000 m, sigma_theta 1.150000 deg")) << b;

  const std::string plain = "fit --logs " + dir + " --residuals track --threads 1 --train-reps 1-99";
  const testing::FitcalRun fixed = testing::RunFitcal(tmp, plain + " --out " + tmp.Path("d.yaml"));
  ASSERT_EQ(fixed.exit_code, 0) << fixed.out << fixed.err;
  EXPECT_FALSE(testing::Has(fixed.out, "weights from the data")) << fixed.out;

  const testing::FitcalRun bad =
      testing::RunFitcal(tmp, fit + " --track-heading sideways --out " + tmp.Path("c.yaml"));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_TRUE(testing::Has(bad.err, "--track-heading")) << bad.err;
}

}  // namespace
}  // namespace fitcal
