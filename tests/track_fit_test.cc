// The track residuals (fit/track_residual.h) and the everyday-driving metrics
// (validation/everyday_driving.h) on a simulated differential drive whose wheels and track are
// all 2 % larger than the nominal (a common scale) and whose ground-truth clock runs 0.15 s late:
//   - the residual's Jacobians (model autodiff chained with Jets) against central differences;
//   - final poses of closed loops cannot see the common scale: the fit holds it at the nominal
//     and says so; the track fit recovers the scale and the clock offset;
//   - drift per metre of a straight run with a 1 % scale error is 1 %, and a constant heading-rate
//     error shows as its deg/m.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "fit/model_fit.h"
#include "fit/residual_choice.h"
#include "fit/track_residual.h"
#include "models/diff_drive/diff_drive_model.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "models/diff_drive/diff_drive_trajectories.h"
#include "sim/model_simulator.h"
#include "validation/everyday_driving.h"
#include "validation/never_worse.h"
#include "validation/time_blocks.h"

namespace fitcal {
namespace {

constexpr double kCommonScale = 1.02;   // true wheels and track / nominal
constexpr double kClockOffsetS = 0.15;  // ground truth stamped this late
constexpr double kGtPositionSigmaM = 0.001;

RobotModelPtr Model() { return ReadRobotModel(YAML::Load(kDiffDriveExampleYaml), "robot.yaml"); }

std::vector<double> TrueParameters(const RobotModelInterface& model) {
  std::vector<double> p = model.robot().nominal;
  for (double& v : p) v *= kCommonScale;
  return p;
}

// Closed calibration loops (UMBmark squares and full circles, both directions), simulated with
// ground-truth noise and the ground-truth clock shifted: the sample of the pose at encoder time t
// is stamped t + kClockOffsetS.
struct Simulated {
  std::vector<RunLog> logs;
  std::vector<AlignedRun> aligned;
  std::vector<const GroundTruthTrack*> tracks;
};

Simulated SimulateLoops(const RobotModelInterface& model, int repetitions) {
  sim::SimulationOptions o;
  o.gt_position_sigma_m = kGtPositionSigmaM;
  o.gt_heading_sigma_rad = 0.002;
  o.wheel_rate_sigma_rad_s = 0.01;
  o.rest_before_s = 1.0;  // longer than the clock offset: the window starts at rest
  o.rest_after_s = 1.0;
  Simulated s;
  for (const auto& run : sim::SimulateRuns(model, TrueParameters(model),
                                           sim::DiffDriveCalibrationTrajectories(repetitions), o)) {
    s.logs.push_back(run.log);
    for (double& t : s.logs.back().ground_truth.t_s) t += kClockOffsetS;
  }
  s.aligned = AlignRuns(s.logs);
  for (const RunLog& log : s.logs) s.tracks.push_back(&log.ground_truth);
  return s;
}

// One run's track cost twice, without and with an OdometryMemo: the memo's answers must be the
// plain cost's own. Built in place: `memoised` keeps the memo's address.
struct PlainAndMemoisedCosts {
  PlainAndMemoisedCosts(const TrackCheckpoints& track, const RobotModelInterface& model,
                        const TrackResidualOptions& options)
      : plain(TrackResidual::Create(track, model, ResidualWeights{}, options)),
        memoised(TrackResidual::Create(track, model, ResidualWeights{}, options, &memo)) {}
  PlainAndMemoisedCosts(const PlainAndMemoisedCosts&) = delete;
  PlainAndMemoisedCosts& operator=(const PlainAndMemoisedCosts&) = delete;

  const TrackResidual& PlainResidual() const {
    return static_cast<const TrackResidual&>(*plain);
  }
  const TrackResidual& MemoisedResidual() const {
    return static_cast<const TrackResidual&>(*memoised);
  }

  OdometryMemo memo;
  std::unique_ptr<ceres::CostFunction> plain, memoised;
};

ModelFitOptions FitOptions(ResidualKind kind, const TrackFitData* track) {
  ModelFitOptions o;
  o.residuals = kind;
  o.track = track;
  o.ceres.num_threads = 1;
  return o;
}

TEST(TrackResidual, JacobiansMatchCentralDifferences) {
  const RobotModelPtr model = Model();
  const Simulated s = SimulateLoops(*model, 1);
  // Both heading forms: from the run's start, and increments between checkpoints (whose
  // residual also depends on the odometry at the checkpoint before).
  for (TrackHeading heading : {TrackHeading::kFromStart, TrackHeading::kIncrements}) {
    TrackResidualOptions track_options;
    track_options.heading = heading;
    const TrackFitData data =
        MakeTrackFitData(s.aligned, s.tracks, ClockGrouping::kPerRun, track_options);
    std::vector<double> p = {0.0425, 0.0418, 0.203};
    double dt = 0.1234;  // between ground-truth samples (0.1 s apart): the interpolant is smooth
    for (const TrackCheckpoints& track : data.runs) {
      std::unique_ptr<ceres::CostFunction> cost(
          TrackResidual::Create(track, *model, ResidualWeights{}, data.options));
      const int m = cost->num_residuals();
      std::vector<double> r(m), j_p(m * 3), j_dt(m);
      const double* parameters[] = {p.data(), &dt};
      double* jacobians[] = {j_p.data(), j_dt.data()};
      ASSERT_TRUE(cost->Evaluate(parameters, r.data(), jacobians));
      const auto residuals_at = [&](const std::vector<double>& q, double t) {
        std::vector<double> out(m);
        const double* at[] = {q.data(), &t};
        cost->Evaluate(at, out.data(), nullptr);
        return out;
      };
      // h: truncation O(h^2) and rounding O(1e-16 / h) both far below the 1e-5 relative tolerance
      // (a Huber kink crossed by the step would show as a gross mismatch, not within it).
      for (int k = 0; k < 4; ++k) {
        const double h = k < 3 ? 1e-7 : 1e-6;
        std::vector<double> plus = p, minus = p;
        double dt_plus = dt, dt_minus = dt;
        if (k < 3) {
          plus[k] += h;
          minus[k] -= h;
        } else {
          dt_plus += h;
          dt_minus -= h;
        }
        const std::vector<double> rp = residuals_at(plus, dt_plus);
        const std::vector<double> rm = residuals_at(minus, dt_minus);
        for (int i = 0; i < m; ++i) {
          const double numeric = (rp[i] - rm[i]) / (2.0 * h);
          const double analytic = k < 3 ? j_p[i * 3 + k] : j_dt[i];
          EXPECT_NEAR(analytic, numeric, 1e-5 * (1.0 + std::abs(numeric)))
              << ToString(heading) << " " << track.run->id << " residual " << i << " parameter "
              << k;
        }
      }
    }
  }
}

// A fit with clock offsets solves by turns, each a new problem at the parameters the last one
// ended at with only the offsets moved (fit/model_fit.cc): the OdometryMemo answers those
// requests. Its answers must be the cost's own to the bit, for a moved offset, for each kind of
// request, and never a stale replay when the parameters move.
TEST(TrackResidual, OdometryMemoAnswersTheCostsOwnNumbersBitForBit) {
  const RobotModelPtr model = Model();
  const Simulated s = SimulateLoops(*model, 1);
  TrackResidualOptions track_options;
  track_options.heading = TrackHeading::kIncrements;
  const TrackFitData data =
      MakeTrackFitData(s.aligned, s.tracks, ClockGrouping::kPerRun, track_options);
  for (const TrackCheckpoints& track : data.runs) {
    const PlainAndMemoisedCosts costs(track, *model, data.options);
    const int m = costs.plain->num_residuals();
    const auto same_bits = [&](std::vector<double> p, double dt, bool with_jacobians) {
      std::vector<double> r[2], j_p[2], j_dt[2];
      const ceres::CostFunction* both[2] = {costs.plain.get(), costs.memoised.get()};
      for (int c = 0; c < 2; ++c) {
        r[c].assign(m, 0.0), j_p[c].assign(m * 3, 0.0), j_dt[c].assign(m, 0.0);
        const double* parameters[] = {p.data(), &dt};
        double* jacobians[] = {j_p[c].data(), j_dt[c].data()};
        EXPECT_TRUE(both[c]->Evaluate(parameters, r[c].data(),
                                       with_jacobians ? jacobians : nullptr));
      }
      return std::memcmp(r[0].data(), r[1].data(), m * sizeof(double)) == 0 &&
             std::memcmp(j_p[0].data(), j_p[1].data(), 3 * m * sizeof(double)) == 0 &&
             std::memcmp(j_dt[0].data(), j_dt[1].data(), m * sizeof(double)) == 0;
    };
    const std::vector<double> p = {0.0425, 0.0418, 0.203};
    std::vector<double> p_next = p;  // a Levenberg-Marquardt step's last digits
    p_next[2] *= 1.0 + 1e-9;
    for (bool with_jacobians : {true, false}) {
      EXPECT_TRUE(same_bits(p, 0.1234, with_jacobians)) << track.run->id;  // kept
      EXPECT_TRUE(same_bits(p, -0.05, with_jacobians)) << track.run->id;   // from the memo
      EXPECT_TRUE(same_bits(p_next, -0.05, with_jacobians)) << track.run->id;  // replayed
      EXPECT_TRUE(same_bits(p, -0.05, with_jacobians)) << track.run->id;       // replayed
    }
    // The search's odometry (OdometryFromStart) shares the memo of the residual-only requests.
    EXPECT_EQ(costs.MemoisedResidual().OdometryFromStart(p.data()),
              costs.PlainResidual().OdometryFromStart(p.data()));
  }
}

// Ceres' bounded trust region evaluates the Jacobian at each candidate point in its line search,
// then the cost alone at the same point; the offsets' search replays the point a solve ended at.
// Where the model's poses are the same with and without Jacobians (the diff drive's analytic
// segment cost), the memo answers those from the evaluation with Jacobians, with the cost's own
// numbers to the bit.
TEST(TrackResidual, OdometryMemoAnswersTheCostAloneFromAnEvaluationWithJacobians) {
  const RobotModelPtr model = Model();
  ASSERT_TRUE(model->SegmentResidualsAlikeWithJacobians());
  const Simulated s = SimulateLoops(*model, 1);
  const TrackFitData data = MakeTrackFitData(s.aligned, s.tracks, ClockGrouping::kPerRun);
  for (const TrackCheckpoints& track : data.runs) {
    const PlainAndMemoisedCosts costs(track, *model, data.options);
    const OdometryMemo& memo = costs.memo;
    const int m = costs.plain->num_residuals();
    std::vector<double> p = {0.0425, 0.0418, 0.203};
    double dt = 0.1234;
    std::vector<double> r(m), j_p(3 * m), j_dt(m), r_memo(m), r_plain(m);
    const double* parameters[] = {p.data(), &dt};
    double* jacobians[] = {j_p.data(), j_dt.data()};
    ASSERT_TRUE(costs.memoised->Evaluate(parameters, r.data(), jacobians));
    ASSERT_EQ(memo.recalled(), 0);
    dt = -0.05;  // the offsets' search moves dt only
    ASSERT_TRUE(costs.memoised->Evaluate(parameters, r_memo.data(), nullptr));
    EXPECT_EQ(memo.recalled(), 1) << track.run->id << ": the replay ran again";
    ASSERT_TRUE(costs.plain->Evaluate(parameters, r_plain.data(), nullptr));
    EXPECT_EQ(std::memcmp(r_memo.data(), r_plain.data(), m * sizeof(double)), 0) << track.run->id;
    EXPECT_EQ(costs.MemoisedResidual().OdometryFromStart(p.data()),
              costs.PlainResidual().OdometryFromStart(p.data()));
    EXPECT_EQ(memo.recalled(), 2) << track.run->id;
  }
}

// The common scale s multiplies every distance the odometry replays and leaves every heading as
// it is, so a closed loop ends where it started whatever s: the final-pose fit holds that
// direction at the nominal. The track sees it at every checkpoint (1 % of the path from the start,
// ~4 cm after 4 m) and recovers the scale and the clock offset.
TEST(TrackFit, RecoversCommonScaleAndClockOffsetThatFinalPosesCannotSee) {
  const RobotModelPtr model = Model();
  const Simulated s = SimulateLoops(*model, 2);
  const std::vector<double> truth = TrueParameters(*model);

  const ModelFitResult final_pose =
      FitModel(s.aligned, *model, FitOptions(ResidualKind::kFinalPose, nullptr));
  ASSERT_TRUE(final_pose.usable);
  ASSERT_FALSE(final_pose.held_directions.empty()) << "the common scale should be undetermined";
  // Held at the nominal: the mean scale of the three lengths stays within a tenth of the 2 %.
  double mean_scale = 0.0;
  for (int k = 0; k < 3; ++k)
    mean_scale += final_pose.parameters[k] / model->robot().nominal[k] / 3;
  EXPECT_NEAR(mean_scale, 1.0, 0.002);

  const TrackFitData data = MakeTrackFitData(s.aligned, s.tracks, ClockGrouping::kPerSession);
  const ModelFitResult track = FitModel(s.aligned, *model, FitOptions(ResidualKind::kTrack, &data));
  ASSERT_TRUE(track.usable) << track.termination << ": " << track.message;
  EXPECT_TRUE(track.held_directions.empty());
  // Tolerances from the noise: ground-truth noise of 1 mm per sample over hundreds of checkpoints
  // of 1-6 m from the start bounds the scale to ~1e-4; the simulator's 50 ms encoder steps and the
  // linear interpolation of the 10 Hz ground truth on 0.5 m circles (chord error v^2 dt^2 / 8 r
  // = 0.1 mm) add less. 0.2 % is a tenth of the injected error.
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(track.parameters[k] / truth[k], 1.0, 0.002) << model->robot().LabelOf(k);
  }
  ASSERT_EQ(track.clock_offsets_s.size(), data.clock_groups.size());
  for (std::size_t g = 0; g < data.clock_groups.size(); ++g) {
    // Each session's offset within four of its own sigmas, and those sigmas small: 20 ms is 4 mm
    // of motion at 0.2 m/s. (The random-walk covariance, fit/serial_covariance.h, gives 10.8 ms
    // here; counting every checkpoint as independent gave under 10.)
    ASSERT_TRUE(track.has_covariance);
    const double sigma = track.clock_offset_sigma_s[g];
    EXPECT_GT(sigma, 0.0);
    EXPECT_LT(sigma, 0.02);
    EXPECT_NEAR(track.clock_offsets_s[g], kClockOffsetS, 4.0 * sigma) << data.clock_groups[g];
  }

  // Without the clock offsets the track residuals are biased by |v| * 0.15 s = 3 cm per checkpoint,
  // and "both" recovers the scale as well.
  const ModelFitResult both = FitModel(s.aligned, *model, FitOptions(ResidualKind::kBoth, &data));
  ASSERT_TRUE(both.usable);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(both.parameters[k] / truth[k], 1.0, 0.002);
}

// --residuals auto: the simulated loops (10 Hz ground truth at 0.2 m/s: a sample every 2 cm, 4 m
// and more of path per run) are a dense track; the same runs with only every 30th ground-truth
// sample kept (one every 0.6 m) are not, and neither are runs cut to their first 1.5 m of path.
TEST(ResidualChoice, DenseLongTracksCallForTrackResiduals) {
  const RobotModelPtr model = Model();
  Simulated s = SimulateLoops(*model, 1);
  const TrackDensity dense = MeasureTrackDensity(s.aligned, s.tracks);
  EXPECT_TRUE(dense.dense) << dense.median_sample_spacing_m << " m, " << dense.median_path_m;
  EXPECT_LT(dense.median_sample_spacing_m, 0.03);

  std::vector<GroundTruthTrack> sparse;
  for (const GroundTruthTrack* track : s.tracks) {
    GroundTruthTrack thin;
    for (std::size_t k = 0; k < track->t_s.size(); k += 30) {
      thin.t_s.push_back(track->t_s[k]);
      thin.world_T_robot.push_back(track->world_T_robot[k]);
    }
    sparse.push_back(thin);
  }
  std::vector<const GroundTruthTrack*> sparse_tracks;
  for (const GroundTruthTrack& t : sparse) sparse_tracks.push_back(&t);
  EXPECT_FALSE(MeasureTrackDensity(s.aligned, sparse_tracks).dense);

  std::vector<AlignedRun> short_runs = s.aligned;
  for (std::size_t i = 0; i < short_runs.size(); ++i) {
    // End each run's window when 1.5 m of ground-truth path lie behind it.
    const GroundTruthTrack& t = *s.tracks[i];
    double path_m = 0.0;
    for (std::size_t k = 1; k < t.t_s.size(); ++k) {
      if (t.t_s[k - 1] < short_runs[i].t_start_s) continue;
      path_m += std::hypot(t.world_T_robot[k].x - t.world_T_robot[k - 1].x,
                           t.world_T_robot[k].y - t.world_T_robot[k - 1].y);
      if (path_m > 1.5) {
        short_runs[i].t_final_s = t.t_s[k];
        break;
      }
    }
  }
  EXPECT_FALSE(MeasureTrackDensity(short_runs, s.tracks).dense);
}

// A straight run of 6 m replayed with a wheel radius 1 % small: every window is 1 % short, so the
// drift is 1 % at every length and no rotation; a 1 % difference between the wheels instead turns
// the robot by (dr / r) (1 m) / b per metre. Then the comparison table of the scale error.
TEST(EverydayDriving, DriftOfAStraightRunWithAScaleErrorAndAHeadingRateError) {
  const RobotModelPtr model = Model();
  const std::vector<double> nominal = model->robot().nominal;
  sim::SimulationOptions o;
  const auto runs =
      sim::SimulateRuns(*model, nominal, {{"straight", 1, {{{0.2, 0.0, 0.0}, 30.0}}}}, o);
  std::vector<RunLog> logs = {runs[0].log};
  const std::vector<AlignedRun> aligned = AlignRuns(logs);
  const std::vector<const GroundTruthTrack*> tracks = {&logs[0].ground_truth};

  std::vector<double> small = nominal;
  small[0] *= 0.99;
  small[1] *= 0.99;
  const EverydayDrivingMetrics scale =
      EvaluateEverydayDriving(*model, small, {}, aligned, tracks, {1.0, 2.0, 5.0}, 1);
  for (const DriftAtLength& d : scale.drift) {
    ASSERT_GT(d.windows, 0);
    // The odometry is sampled at the nearest encoder time (50 ms, 1 cm at 0.2 m/s) to each
    // ground-truth time, on both ends of a window: the window's odometry length is off by at most
    // that, 1 % of 1 m; the mean over windows cancels most of it.
    EXPECT_NEAR(d.translation_percent, 1.0, 0.05) << d.length_m;
    EXPECT_NEAR(d.rotation_deg_per_m, 0.0, 1e-6) << d.length_m;
  }

  std::vector<double> uneven = nominal;
  uneven[0] *= 1.01;  // one wheel 1 % larger: the odometry turns at 0.01 v / b
  const EverydayDrivingMetrics turn =
      EvaluateEverydayDriving(*model, uneven, {}, aligned, tracks, {1.0}, 1);
  // d theta / d s = (v_R' - v_L') / (b v) = 0.01 / b per metre of ground-truth path.
  const double expected_deg_per_m = RadToDeg(0.01 / nominal[2]);
  EXPECT_NEAR(turn.drift[0].rotation_deg_per_m, expected_deg_per_m, 0.02 * expected_deg_per_m);

  // The table `fit` and `generalise` print (validation/never_worse.h CompareEverydayDriving):
  // the nominal replays its own simulation, so its drift is the sampling's (under 0.05 %, as
  // above); the small wheels' 1 % rise is said beside each drift row. The nominal against itself:
  // no note, nothing judged worse.
  const CalibrationCandidate as_built{"nominal", nominal}, scaled{"small", small};
  const EverydayDrivingComparison c =
      CompareEverydayDriving(*model, as_built, scaled, aligned, tracks, 1);
  int drift_rows = 0;
  for (const std::string& row : c.rows) {
    double length_m = 0.0, before = -1.0, after = -1.0;
    int windows = 0;
    if (std::sscanf(row.c_str(), "  drift %lf m [%%] (%d windows) %lf %lf", &length_m, &windows,
                    &before, &after) != 4) {
      continue;
    }
    ++drift_rows;
    EXPECT_NE(row.find("  worse"), std::string::npos) << row;
    if (length_m < 1.0) continue;  // 1 cm of sampling is 2 % of 0.5 m: checked from 1 m, as above
    EXPECT_NEAR(before, 0.0, 0.05) << row;
    EXPECT_NEAR(after, 1.0, 0.05) << row;
  }
  EXPECT_EQ(drift_rows, 4);  // 0.5, 1, 2 and 5 m on a 6 m run
  const EverydayDrivingComparison same =
      CompareEverydayDriving(*model, as_built, as_built, aligned, tracks, 1);
  ASSERT_EQ(same.rows.size(), c.rows.size());
  for (const std::string& row : same.rows) EXPECT_EQ(row.find("worse"), std::string::npos) << row;
  for (const NeverWorseJudgement& j : same.judgements) EXPECT_FALSE(j.Worse()) << j.measure;
}

// A straight run of 6 m at 0.2 m/s cut into four blocks: contiguous, every sample once, each
// 1.5 m of path to within one encoder interval (1 cm), each started and ended on the ground truth.
TEST(TimeBlocks, CutARunIntoBlocksOfEqualPath) {
  const RobotModelPtr model = Model();
  const auto sim = sim::SimulateRuns(*model, model->robot().nominal,
                                     {{"free", 1, {{{0.2, 0.0, 0.0}, 30.0}}}}, {});
  const std::vector<RunLog> logs = {sim[0].log};
  const AlignedRun run = AlignRuns(logs)[0];
  const std::vector<AlignedRun> blocks = CutIntoTimeBlocks(run, 4);
  ASSERT_EQ(blocks.size(), 4u);
  std::size_t samples = 0;
  double t = run.t_start_s;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const AlignedRun& block = blocks[b];
    EXPECT_EQ(block.repetition, static_cast<int>(b) + 1);
    EXPECT_EQ(block.track, run.track) << block.id;  // replayed against its run's track
    EXPECT_NEAR(block.t_start_s, t, 1e-9);
    samples += block.samples.size();
    t = block.t_final_s;
    const double path_m = std::hypot(block.final_ground_truth.x - block.start.x,
                                     block.final_ground_truth.y - block.start.y);
    // The first and last blocks include the ramps and rests; each holds 1.5 m of path.
    EXPECT_NEAR(path_m, 1.5, 0.011) << block.id;
  }
  EXPECT_EQ(samples, run.samples.size());
  EXPECT_NEAR(t, run.t_final_s, 1e-9);
  EXPECT_THROW(CutIntoTimeBlocks(run, 0), std::invalid_argument);
}

// A run that turns, rests 3 s and turns back, with the ground truth stamped 0.3 s late: its
// equal-path half falls 0.2 m into the second turn, where the lag moves the ground truth's pose
// by 0.06 m and 0.09 rad. The boundary moves into the rest (within a quarter block, 0.5 m): every
// ground-truth sample within the lag bound (0.5 s) of it shows the robot still, so the true
// parameters replay both blocks to their ground truth (CF 0.108 with the cut mid-turn, measured).
TEST(TimeBlocks, BoundaryMovesToWhereTheClockLagMovesNothing) {
  const RobotModelPtr model = Model();
  sim::SimulationOptions o;
  o.rest_before_s = 1.0;
  o.rest_after_s = 1.0;
  const double turn_rad_s = 0.3, rest_s = 3.0;
  const auto sim = sim::SimulateRuns(
      *model, model->robot().nominal,
      {{"free", 1, {{{0.2, 0.0, turn_rad_s}, 9.0}, {{0.0, 0.0, 0.0}, rest_s},
                    {{0.2, 0.0, -turn_rad_s}, 11.0}}}},
      o);
  std::vector<RunLog> logs = {sim[0].log};
  const double lag_s = 0.3;
  for (double& t : logs[0].ground_truth.t_s) t += lag_s;
  const AlignedRun run = AlignRuns(logs)[0];
  const std::vector<AlignedRun> blocks = CutIntoTimeBlocks(run, 2);
  ASSERT_EQ(blocks.size(), 2u);
  // The rest spans [10, 13] s from the start with ramps of 0.2 s on each side, [10.5, 13.5] s on
  // the ground truth's late clock; within the lag bound (0.5 s) of the cut: [11.0, 12.6] s.
  const double cut_s = blocks[0].t_final_s - run.t_start_s;
  EXPECT_GE(cut_s, 1.0 + 9.0 + 0.2 + lag_s + 0.5 - 1e-9);
  EXPECT_LE(cut_s, 1.0 + 9.0 + rest_s - 0.2 + lag_s - 0.5 + 1e-9);
  const EverydayDrivingMetrics m = EvaluateEverydayDriving(
      *model, model->robot().nominal, {}, blocks, TracksOf(blocks), {1.0}, 1);
  ASSERT_EQ(m.per_run_cf.size(), 2u);
  // Noise-free encoders and ground truth: what is left is the replay's integration of the
  // ramps on the encoder grid, far below the 0.06 m a cut in the turn costs.
  for (double cf : m.per_run_cf) EXPECT_LT(cf, 1e-3);
}

}  // namespace
}  // namespace fitcal
