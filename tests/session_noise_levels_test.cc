// Weights per session where sessions differ (fit/noise_levels.h). Data of the independent
// simulator (tests/independent_sim/: no fitcal code): a differential drive without slip, so the
// odometry is exact up to its 4096-tick encoders, and a ground truth sampled at the encoder times
// with white noise added here - sigma_xy per axis, sigma_theta on the heading, every sample but the
// first (the start is exact, so each checkpoint from the start sees exactly that noise, as in
// noise_levels_test.cc). Two sessions (trajectory labels "calm" and "shaky"), two ~20 m everyday
// runs each:
// - noise 3x apart: each session's levels within four standard errors of its truth (the relative
//   standard error of a sigma from its session's checkpoint count, below), and the calibration
//   with per-session weights closer to the truth than with one level for the data set, summed
//   over kSeeds seeds;
// - the same noise: no session differs, and the fit is byte-equal to the per-data-set estimate;
// - through the command line: the per-session line printed and written into the objective.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "fit/model_fit.h"
#include "fit/track_residual.h"
#include "io/dataset.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "tests/independent_sim/everyday_drive_sim.h"
#include "tests/test_files.h"

namespace fitcal {
namespace {


constexpr double kCalmPositionM = 0.001;
constexpr double kCalmHeadingRad = 0.005;  // 0.29 deg
constexpr double kShakyFactor = 3.0;
constexpr int kRunsPerSession = 2;
constexpr int kSeeds = 10;

struct SessionNoiseSpec {
  std::string label;
  double position_m = 0.0;
  double heading_rad = 0.0;
};

// Two sessions of kRunsPerSession runs each, written as a data set under `dir`.
void WriteTwoSessions(const std::string& dir, const SessionNoiseSpec& a, const SessionNoiseSpec& b,
                      std::uint64_t seed) {
  independent_sim::ContactPhysics no_slip;
  no_slip.traction_slip_per_m_s2 = 0.0;
  no_slip.walk_sigma = 0.0;
  independent_sim::Sensors sensors;
  sensors.mocap_xy_sigma_m = 0.0;
  sensors.mocap_theta_sigma_rad = 0.0;
  // A sample at every encoder time, 25 mm apart at speed: the checkpoints fall where the ground
  // truth's path crosses each 0.5 m (fit/segment_cost.h), and a noise step comparable to the
  // motion between samples would pick the samples with large noise as checkpoints.
  sensors.encoder_period_s = 0.05;
  sensors.mocap_period_s = sensors.encoder_period_s;
  independent_sim::Drive drive;
  drive.length_m = 20.0;
  drive.speed_m_s = 0.5;
  drive.spin_rate_rad_s = 2.0;
  std::mt19937_64 noise(seed * 7919 + 1);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<independent_sim::LabelledRun> runs;
  for (const SessionNoiseSpec& s : {a, b}) {
    for (int k = 1; k <= kRunsPerSession; ++k) {
      independent_sim::SimulatedRun run = independent_sim::SimulateDiffDrive(
          independent_sim::DiffDriveGeometry{}, no_slip, sensors, drive, seed * 100 + runs.size());
      for (std::size_t i = 1; i < run.mocap.size(); ++i) {
        run.mocap[i].x += s.position_m * normal(noise);
        run.mocap[i].y += s.position_m * normal(noise);
        run.mocap[i].theta += s.heading_rad * normal(noise);
      }
      runs.push_back({s.label, k, run});
    }
  }
  independent_sim::WriteLabelledDataSet(dir, runs, {0.042, 0.042, 0.2}, sensors);
}

struct Loaded {
  RobotModelPtr model;
  std::vector<RunLog> logs;
  std::vector<AlignedRun> runs;
};

Loaded Load(const std::string& dir) {
  Loaded out;
  const io::DatasetIndex index = io::ReadDatasetIndex(dir);
  out.model = ReadRobotModelFile(index.robot_path);
  out.logs = io::LoadDataset(index, out.model->robot()).runs;
  out.runs = AlignRuns(out.logs);
  return out;
}

ModelFitResult FitWithEstimatedWeights(const Loaded& d, const TrackFitData& track,
                                       bool per_session) {
  ModelFitOptions o;
  o.residuals = ResidualKind::kTrack;
  o.track = &track;
  o.estimate_weights = true;
  o.noise_levels_per_session = per_session;
  o.ceres.num_threads = 1;
  return FitModel(d.runs, *d.model, o);
}

// Relative standard error of a sigma from one session's runs whose checkpoints weigh 1/K each
// (noise_levels_test.cc): 0.5 sqrt(sum_i 2 / (dimension K_i)) / N.
double RelativeStandardError(const TrackFitData& track, const std::vector<int>& runs,
                             int dimension) {
  double variance = 0.0;
  for (int i : runs) variance += 2.0 / (dimension * track.runs[i].segments.size());
  return 0.5 * std::sqrt(variance) / static_cast<double>(runs.size());
}

// Squared relative error of the three geometric parameters against the simulator's truth.
double SquaredRelativeError(const std::vector<double>& p) {
  const independent_sim::DiffDriveGeometry truth;
  const double t[] = {truth.r_right_m, truth.r_left_m, truth.separation_m};
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) sum += std::pow((p[k] - t[k]) / t[k], 2);
  return sum;
}

TEST(SessionNoiseLevels, SessionsWhoseNoiseDiffers3xGetTheirOwnLevels) {
  const SessionNoiseSpec calm{"calm", kCalmPositionM, kCalmHeadingRad};
  const SessionNoiseSpec shaky{"shaky", kShakyFactor * kCalmPositionM,
                               kShakyFactor * kCalmHeadingRad};
  double per_session_error = 0.0, pooled_error = 0.0;
  int closer = 0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    testing::TempDir tmp;
    WriteTwoSessions(tmp.Path("data"), calm, shaky, seed);
    const Loaded d = Load(tmp.Path("data"));
    const TrackFitData track = MakeTrackFitData(d.runs, TracksOf(d.runs), ClockGrouping::kNone);
    const ModelFitResult fit = FitWithEstimatedWeights(d, track, true);
    const ModelFitResult pooled = FitWithEstimatedWeights(d, track, false);
    ASSERT_TRUE(fit.usable && pooled.usable) << fit.message << pooled.message;
    const NoiseLevels& levels = fit.noise_levels;
    const SessionNoise& s = levels.sessions;
    ASSERT_EQ(s.names, (std::vector<std::string>{"calm", "shaky"}));
    EXPECT_TRUE(s.Differs(kTrackPosition) && s.Differs(kTrackHeading)) << NoiseLevelsText(levels);
    for (int session = 0; session < 2; ++session) {
      const SessionNoiseSpec& truth = session == 0 ? calm : shaky;
      std::vector<int> runs;
      for (std::size_t i = 0; i < s.of_run.size(); ++i) {
        if (s.of_run[i] == session) runs.push_back(static_cast<int>(i));
      }
      EXPECT_NEAR(s.sigma[kTrackPosition][session] / truth.position_m, 1.0,
                  4.0 * RelativeStandardError(track, runs, 2))
          << truth.label << ", seed " << seed << ": " << NoiseLevelsText(levels);
      EXPECT_NEAR(s.sigma[kTrackHeading][session] / truth.heading_rad, 1.0,
                  4.0 * RelativeStandardError(track, runs, 1))
          << truth.label << ", seed " << seed << ": " << NoiseLevelsText(levels);
    }
    const double e = SquaredRelativeError(fit.parameters);
    const double e_pooled = SquaredRelativeError(pooled.parameters);
    std::printf("seed %d: relative error per session %.3e, pooled %.3e\n", seed, std::sqrt(e),
                std::sqrt(e_pooled));
    per_session_error += e;
    pooled_error += e_pooled;
    closer += e < e_pooled;
  }
  std::printf("over %d seeds: rms relative error per session %.3e, pooled %.3e; closer in %d\n",
              kSeeds, std::sqrt(per_session_error / kSeeds), std::sqrt(pooled_error / kSeeds),
              closer);
  EXPECT_LT(per_session_error, pooled_error);
}

TEST(SessionNoiseLevels, SessionsWithTheSameNoiseArePooledByteEqual) {
  const SessionNoiseSpec a{"calm", kCalmPositionM, kCalmHeadingRad};
  const SessionNoiseSpec b{"shaky", kCalmPositionM, kCalmHeadingRad};
  testing::TempDir tmp;
  WriteTwoSessions(tmp.Path("data"), a, b, 1);
  const Loaded d = Load(tmp.Path("data"));
  const TrackFitData track = MakeTrackFitData(d.runs, TracksOf(d.runs), ClockGrouping::kNone);
  const ModelFitResult fit = FitWithEstimatedWeights(d, track, true);
  const ModelFitResult data_set = FitWithEstimatedWeights(d, track, false);
  ASSERT_TRUE(fit.usable) << fit.message;
  EXPECT_FALSE(fit.noise_levels.sessions.AnyDiffers()) << NoiseLevelsText(fit.noise_levels);
  ASSERT_EQ(fit.parameters.size(), data_set.parameters.size());
  EXPECT_EQ(std::memcmp(fit.parameters.data(), data_set.parameters.data(),
                        fit.parameters.size() * sizeof(double)),
            0);
  EXPECT_EQ(NoiseLevelsText(fit.noise_levels), NoiseLevelsText(data_set.noise_levels));
}

TEST(SessionNoiseLevels, FitPrintsAndRecordsTheLevelsPerSession) {
  testing::TempDir tmp;
  WriteTwoSessions(tmp.Path("data"), {"calm", kCalmPositionM, kCalmHeadingRad},
                   {"shaky", kShakyFactor * kCalmPositionM, kShakyFactor * kCalmHeadingRad}, 1);
  const testing::FitcalRun r = testing::RunFitcal(
      tmp, "fit --logs " + tmp.Path("data") +
               " --residuals track --track-heading from-start --train-reps 1-99 --threads 1"
               " --weights estimated --out " + tmp.Path("cal.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  // Two sessions: the one farther from their pooled level leaves the pool (either may).
  const std::string levels = R"([0-9.e-]+ m \(session (calm|shaky)(: differs, Bartlett p = )"
                             R"([0-9.e-]+)?\), [0-9.e-]+ m \(session (calm|shaky)[^)]*\))";
  const std::string line = R"(\n  track position )" + levels + R"(\n  track heading )";
  EXPECT_TRUE(std::regex_search(r.out, std::regex(line))) << r.out;
  EXPECT_TRUE(testing::Has(r.out, ": differs, Bartlett p = ")) << r.out;
  const std::string cal = testing::ReadFileBytes(tmp.Path("cal.yaml"));
  EXPECT_TRUE(std::regex_search(
      cal, std::regex("weights from the data: track position " + levels + "; track heading ")))
      << cal;
}

}  // namespace
}  // namespace fitcal
