// The generic generalisation path (validation/generalisation.h) on the test-only unicycle
// (tests/models/unicycle_test_model.h): two path types whose final poses are known in closed
// form, so the held-out CF of every candidate on every split is computed here independently of
// the replay, the fit and the scoring.
//
// Path type "line": drive straight D metres. Path type "spin": turn in place by Theta, rest, then
// drive straight D. The rest is longer than the simulator's ramps, so no encoder interval both
// turns and drives: the replay's step (Eq. 4 form, odometry/replay.h) is then exact, and a robot
// with parameters (r, k) whose true values are (r_t, k_t) dead-reckons
//   Theta' = k Theta / k_t,  D' = r D / r_t,  final pose (D' cos Theta', D' sin Theta', Theta')
// against the truth (D cos Theta, D sin Theta, Theta), both from the origin.

#include "validation/generalisation.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "fit/segment_cost.h"
#include "models/model_registry.h"
#include "tests/model_support.h"
#include "tests/models/unicycle_test_model.h"
#include "sim/model_simulator.h"

namespace fitcal {
namespace {

constexpr double kTrueRadius = 0.052;  // nominal 0.05 (example YAML), bounds [0.04, 0.06]
constexpr double kTrueGain = 0.53;     // nominal 0.5, bounds [0.4, 0.6]
constexpr double kSpeed = 0.2;         // m/s
constexpr double kTurnRate = 0.5;      // rad/s
// Noise-free data: the fit's parameters are exact to the solver's tolerance (~1e-9 relative),
// which moves a CF over 2 m runs by far less than this.
constexpr double kCfTolerance = 1e-6;

struct Shape {
  const char* label;
  double turn_rad;  // 0: a line
  double distance_m;
};

constexpr Shape kShapes[] = {
    {"line_a", 0.0, 2.0}, {"line_b", 0.0, 1.4}, {"spin_a", 1.2, 1.0}, {"spin_b", -0.8, 1.6}};

sim::TrajectorySpec Spec(const Shape& s) {
  sim::TrajectorySpec spec;
  spec.label = s.label;
  if (s.turn_rad != 0.0) {
    const double rate = std::copysign(kTurnRate, s.turn_rad);
    spec.segments.push_back({Twist{0.0, 0.0, rate}, s.turn_rad / rate});
    spec.segments.push_back({Twist{0.0, 0.0, 0.0}, 1.0});  // > 2 ramps: no interval mixes both
  }
  spec.segments.push_back({Twist{kSpeed, 0.0, 0.0}, s.distance_m / kSpeed});
  return spec;
}

// Eq. 14 for one run from the closed form above.
double ExpectedCf(const Shape& s, double r, double k) {
  const double turn = k * s.turn_rad / kTrueGain, distance = r * s.distance_m / kTrueRadius;
  const double dx = s.distance_m * std::cos(s.turn_rad) - distance * std::cos(turn);
  const double dy = s.distance_m * std::sin(s.turn_rad) - distance * std::sin(turn);
  return std::sqrt(dx * dx + dy * dy + (s.turn_rad - turn) * (s.turn_rad - turn));
}

double MeanExpectedCf(const std::vector<int>& shapes, double r, double k) {
  double sum = 0.0;
  for (int i : shapes) sum += ExpectedCf(kShapes[i], r, k);
  return sum / shapes.size();
}

const CandidateScore& Find(const SplitScores& s, const std::string& name) {
  for (const CandidateScore& c : s.candidates)
    if (c.name == name) return c;
  ADD_FAILURE() << "no candidate " << name;
  return s.candidates.front();
}

class GeneralisationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ = testing::ExampleModel("test_unicycle");
    std::vector<sim::TrajectorySpec> specs;
    for (const Shape& s : kShapes) specs.push_back(Spec(s));
    for (const sim::ModelSimulatedRun& run :
         sim::SimulateRuns(*model_, {kTrueRadius, kTrueGain}, specs, sim::SimulationOptions{})) {
      runs_.push_back(AlignRun(run.log));
    }
  }

  RobotModelPtr model_;
  std::vector<AlignedRun> runs_;
};

TEST_F(GeneralisationTest, PathTypeSplitsTrainOnOneAndScoreTheOther) {
  const std::vector<GeneralisationSplit> splits = PathTypeSplits(runs_);
  ASSERT_EQ(splits.size(), 2u);
  EXPECT_EQ(splits[0].train_name, "line");
  EXPECT_EQ(splits[0].test_name, "spin");
  EXPECT_EQ(splits[0].train, (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(splits[0].test, (std::vector<std::size_t>{2, 3}));
  const double r0 = model_->robot().nominal[0], k0 = model_->robot().nominal[1];

  // Lines determine the radius only: the fit finds the true radius and keeps the turn gain at
  // its nominal (held: the lines carry no information on it).
  const SplitScores line_to_spin = EvaluateSplit(*model_, runs_, splits[0], {});
  EXPECT_NEAR(Find(line_to_spin, "nominal").test.cf, MeanExpectedCf({2, 3}, r0, k0), kCfTolerance);
  const CandidateScore& fit = Find(line_to_spin, "fit");
  ASSERT_TRUE(fit.usable);
  EXPECT_EQ(fit.held_directions, 1);
  EXPECT_NEAR(fit.train.cf, 0.0, kCfTolerance);
  EXPECT_NEAR(fit.test.cf, MeanExpectedCf({2, 3}, kTrueRadius, k0), kCfTolerance);
  EXPECT_GT(fit.test.cf, 0.01);  // the held gain is visible on the spins

  // Spins with a drive determine both: the lines are reproduced.
  const SplitScores spin_to_line = EvaluateSplit(*model_, runs_, splits[1], {});
  EXPECT_NEAR(Find(spin_to_line, "nominal").test.cf, MeanExpectedCf({0, 1}, r0, k0), kCfTolerance);
  EXPECT_NEAR(Find(spin_to_line, "fit").test.cf, 0.0, kCfTolerance);
  EXPECT_EQ(Find(spin_to_line, "fit").held_directions, 0);
}

TEST_F(GeneralisationTest, LeaveOneSessionOutHoldsOutEverySessionOnce) {
  const std::vector<GeneralisationSplit> splits =
      LeaveOneSessionOutSplits(runs_, SessionKey::kLabel);
  ASSERT_EQ(splits.size(), 4u);
  std::vector<SplitScores> folds;
  for (const GeneralisationSplit& s : splits) {
    ASSERT_EQ(s.test.size(), 1u);
    ASSERT_EQ(s.train.size(), 3u);
    folds.push_back(EvaluateSplit(*model_, runs_, s, {}));
  }
  const std::vector<FoldSummary> summary = SummariseFolds(folds);
  ASSERT_GE(summary.size(), 2u);
  EXPECT_EQ(summary[0].name, "nominal");
  EXPECT_EQ(summary[0].folds, 4);
  const double r0 = model_->robot().nominal[0], k0 = model_->robot().nominal[1];
  EXPECT_NEAR(summary[0].mean_session_cf, MeanExpectedCf({0, 1, 2, 3}, r0, k0), kCfTolerance);
  // Every fold trains on a spin with a drive: both parameters determined, every session
  // reproduced.
  EXPECT_EQ(summary[1].name, "fit");
  EXPECT_NEAR(summary[1].run_cf, 0.0, kCfTolerance);

  // Path type + repetition: every run here is repetition 1, so two sessions.
  EXPECT_EQ(LeaveOneSessionOutSplits(runs_, SessionKey::kPathTypeAndRepetition).size(), 2u);
}

// Sousa et al.'s OptiOdom candidate scores the position from the start at checkpoints along the
// track, so it sees what a closed path hides from its final pose: a run that drives D metres out
// and D back ends where it started whatever the radius, while its checkpoints on the way out are
// D' = r D / r_t from the start. Trained on such runs, the final-pose fit learns nothing about r
// (and holds it), the OptiOdom candidate recovers the true radius - which the lines then confirm.
TEST(GeneralisationOptiOdom, CheckpointsSeeWhatAClosedPathHidesFromItsFinalPose) {
  const RobotModelPtr model = testing::ExampleModel("test_unicycle");
  std::vector<sim::TrajectorySpec> specs;
  for (const char* label : {"outback_a", "outback_b"}) {
    sim::TrajectorySpec spec;
    spec.label = label;
    spec.segments = {{Twist{kSpeed, 0.0, 0.0}, 8.0},
                     {Twist{0.0, 0.0, 0.0}, 1.0},
                     {Twist{-kSpeed, 0.0, 0.0}, 8.0}};
    specs.push_back(spec);
  }
  specs.push_back(Spec(kShapes[0]));
  specs.push_back(Spec(kShapes[1]));
  // Ground truth at the encoder instants: the checkpoints need no interpolation, so noise-free
  // data are reproduced to the solver's tolerance.
  sim::SimulationOptions sim_options;
  sim_options.ground_truth_period_s = sim_options.encoder_period_s;
  std::vector<AlignedRun> runs;
  std::vector<RunLog> logs;
  for (const sim::ModelSimulatedRun& run :
       sim::SimulateRuns(*model, {kTrueRadius, kTrueGain}, specs, sim_options)) {
    runs.push_back(AlignRun(run.log));
    logs.push_back(run.log);
  }
  std::vector<std::vector<Segment>> checkpoints;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    checkpoints.push_back(MakeCheckpointsFromStart(runs[i], logs[i].ground_truth, 0.5));
  }
  // 3.2 m out and back: a checkpoint after every 0.5 m (six), and the end.
  ASSERT_EQ(checkpoints[0].size(), 7u);
  const GeneralisationSplit split{"outback", "line", {0, 1}, {2, 3}};
  const SplitScores scores =
      EvaluateSplit(*model, runs, split, {}, TrackCandidates{&checkpoints, nullptr, {}});
  const double r0 = model->robot().nominal[0], k0 = model->robot().nominal[1];
  const double nominal_cf = MeanExpectedCf({0, 1}, r0, k0);
  ASSERT_GT(nominal_cf, 0.05);
  EXPECT_NEAR(Find(scores, "fit").test.cf, nominal_cf, kCfTolerance);
  const CandidateScore optiodom = Find(scores, "optiodom");
  ASSERT_TRUE(optiodom.usable);
  EXPECT_NEAR(optiodom.parameters[0], kTrueRadius, 1e-8);
  EXPECT_NEAR(optiodom.test.cf, 0.0, kCfTolerance);
  // Without checkpoints there is no such candidate.
  for (const CandidateScore& c : EvaluateSplit(*model, runs, split, {}).candidates) {
    EXPECT_NE(c.name, "optiodom");
  }
}

// Checkpoints begin at the start, end after every `spacing` of ground-truth path since the last
// one, and at the run's end.
TEST(GeneralisationOptiOdom, CheckpointsFollowTheGroundTruthPath) {
  const RobotModelPtr model = testing::ExampleModel("test_unicycle");
  sim::SimulationOptions sim_options;
  sim_options.ground_truth_period_s = sim_options.encoder_period_s;
  const sim::ModelSimulatedRun run =
      sim::SimulateRuns(*model, {kTrueRadius, kTrueGain}, {Spec(kShapes[1])}, sim_options)[0];
  const AlignedRun aligned = AlignRun(run.log);
  const std::vector<Segment> c = MakeCheckpointsFromStart(aligned, run.log.ground_truth, 0.3);
  ASSERT_EQ(c.size(), 5u);  // 1.4 m: after 0.3, 0.6, 0.9 and 1.2 m, then the end
  for (std::size_t k = 0; k < c.size(); ++k) {
    EXPECT_EQ(c[k].begin, 0u);
    if (k + 1 < c.size()) {
      // The first encoder boundary at or past the checkpoint: within one interval (0.01 m).
      EXPECT_GE(c[k].path_length_m, 0.3 * (k + 1) - 1e-12);
      EXPECT_LT(c[k].path_length_m, 0.3 * (k + 1) + kSpeed * sim_options.encoder_period_s);
      EXPECT_NEAR(c[k].ground_truth_start_T_end.x, c[k].path_length_m, 1e-9);
    }
  }
  EXPECT_EQ(c.back().end, aligned.samples.size());
  EXPECT_NEAR(c.back().ground_truth_start_T_end.x, 1.4, 1e-9);
  EXPECT_THROW(MakeCheckpointsFromStart(aligned, run.log.ground_truth, 0.0), std::invalid_argument);
}

// A ground truth sparser than the encoders (every 0.25 s, encoders every 0.05 s) is a straight
// line between its samples, which lags a robot slowing down: each checkpoint sits on a sample
// (stop 72's D-F1: between samples the flower's checkpoints read the stop 5-6 mm short and track
// fits wrote radii 0.27 % small), past its spacing by less than one sample's travel.
TEST(GeneralisationOptiOdom, CheckpointsSitOnASparseGroundTruthsSamples) {
  const RobotModelPtr model = testing::ExampleModel("test_unicycle");
  sim::SimulationOptions sim_options;
  sim_options.ground_truth_period_s = 5 * sim_options.encoder_period_s;
  const sim::ModelSimulatedRun run =
      sim::SimulateRuns(*model, {kTrueRadius, kTrueGain}, {Spec(kShapes[1])}, sim_options)[0];
  const AlignedRun aligned = AlignRun(run.log);
  const std::vector<double> t = BoundaryTimes(aligned);
  const std::vector<double>& samples = run.log.ground_truth.t_s;
  const std::vector<Segment> c = MakeCheckpointsFromStart(aligned, run.log.ground_truth, 0.33);
  ASSERT_EQ(c.size(), 5u);  // 1.4 m: four checkpoints 0.33 m apart or a little more, the end
  double previous_m = 0.0;
  for (std::size_t k = 0; k + 1 < c.size(); ++k) {
    const double at = t[c[k].end];
    const auto sample = std::lower_bound(samples.begin(), samples.end(), at - 1e-9);
    ASSERT_NE(sample, samples.end());
    EXPECT_NEAR(*sample, at, 1e-9) << "checkpoint " << k << " between samples";
    EXPECT_GE(c[k].path_length_m - previous_m, 0.33 - 1e-12);
    EXPECT_LT(c[k].path_length_m - previous_m,
              0.33 + kSpeed * sim_options.ground_truth_period_s + 1e-9);
    previous_m = c[k].path_length_m;
  }
}

TEST(GeneralisationSplits, PredicateSplitsGoBothWaysAndNeedBothSides) {
  std::vector<AlignedRun> runs(3);
  runs[0].trajectory = "circular/1";
  runs[1].trajectory = "square_2";
  runs[2].trajectory = "circular/3";
  EXPECT_EQ(PathTypeOf(runs[0].trajectory), "circular");
  EXPECT_EQ(PathTypeOf(runs[1].trajectory), "square");
  const auto circles = [](const AlignedRun& r) { return PathTypeOf(r.trajectory) == "circular"; };
  const std::vector<GeneralisationSplit> s = PredicateSplits(runs, circles, "c", "s");
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].train, (std::vector<std::size_t>{0, 2}));
  EXPECT_EQ(s[1].train, (std::vector<std::size_t>{1}));
  EXPECT_TRUE(PredicateSplits(
                  runs, [](const AlignedRun&) { return true; }, "a", "b")
                  .empty());
}

}  // namespace
}  // namespace fitcal
