// End-to-end tests of the effect tracing (diagnosis/diagnose.h) on small simulated flower data
// sets.

#include "diagnosis/diagnose.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "fit/run_split.h"
#include "models/model_registry.h"
#include "models/omni3/omni3_robot_model.h"
#include "tests/flower_scenario.h"
#include "tests/test_paths.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace diagnose_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

Omni3Robot NominalRobot() { return ReadOmni3Robot(FITCAL_SOURCE_DIR + "/data/robots/apr02.yaml"); }

// The nominal robot on the model seam, which Diagnose works through.
std::shared_ptr<const Omni3Model> NominalModel() { return Omni3ModelOf(NominalRobot()); }

struct Data {
  std::vector<TrackRun> training, validation;
};

// Palacin's flower with `repetitions` of every trajectory on simulator seed `seed`.
sim::FlowerSimulation Flower(int repetitions, std::uint64_t seed) {
  sim::FlowerSimulation o = sim::PalacinFlower();
  o.repetitions = repetitions;
  o.options.seed = seed;
  return o;
}

// Injects the library effect `id` at its registry's realistic magnitude; returns it.
effects::EffectValue InjectTypical(effects::EffectId id, sim::FlowerSimulation* o) {
  effects::EffectValue truth;
  truth.id = id;
  truth.value = effects::Info(id).typical;
  o->options.stepped->injected_effects = {truth};
  return truth;
}

// The runs of `o`, commanded with the nominal robot; `training_repetitions` train, the rest
// validate.
Data Simulate(sim::FlowerSimulation o, const std::vector<int>& training_repetitions = {1}) {
  o.options.stepped->commanded_parameters = sim::ParameterVector(NominalRobot().nominal);
  std::vector<RunLog> logs = sim::SimulateFlowerLogs(o);
  SplitOf<TrackRun> split = SplitByRepetition(PrepareTrackRuns(logs), training_repetitions);
  return {std::move(split.training), std::move(split.validation)};
}

// Every fitted candidate's verdict reports its held-out test as it came out: "not significant"
// exactly when p is not below the round's threshold, and a significant candidate that is not
// accepted names the rule that turned it down.
void ExpectVerdictsMatchTheirTests(const DiagnoseResult& r) {
  for (const DiagnoseRound& round : r.rounds) {
    for (const CandidateResult& c : round.candidates) {
      if (!c.fitted) continue;
      const bool says_not_significant = c.verdict.rfind("not significant", 0) == 0;
      EXPECT_EQ(says_not_significant, !(c.p_value < round.threshold))
          << effects::Info(c.id).name << ": p " << c.p_value << ", threshold " << round.threshold
          << ", verdict '" << c.verdict << "'";
      if (c.significant && !c.accepted) {
        EXPECT_NE(c.verdict.find("(rule: "), std::string::npos) << c.verdict;
      }
    }
  }
}

// Every identifiable library effect, injected at its registry's realistic magnitude into
// otherwise clean simulated data (36 flower trajectories x 2 repetitions: repetition 1 trains,
// 2 validates): diagnose must accept exactly that effect, recover its parameters and match the
// true model's validation CF.
class LibraryEffectTest : public ::testing::TestWithParam<effects::EffectId> {};

TEST_P(LibraryEffectTest, DiagnosePicksRecoversAndMatchesTrueModel) {
  const effects::EffectInfo& info = effects::Info(GetParam());
  sim::FlowerSimulation o = Flower(2, 11);
  const effects::EffectValue truth = InjectTypical(info.id, &o);
  const Data d = Simulate(o);
  const auto model = NominalModel();
  const DiagnoseResult r = Diagnose(d.training, d.validation, *model);
  SCOPED_TRACE(FormatDiagnoseReport(r, *model));
  ASSERT_GE(r.final_fit.effects.size(), 1u);
  EXPECT_EQ(r.final_fit.effects.front().id, info.id)
      << effects::Info(r.final_fit.effects.front().id).name;
  EXPECT_EQ(r.final_fit.effects.size(), 1u);
  EXPECT_TRUE(r.effects_named);
  const effects::EffectValue& got = r.final_fit.effects.front();
  for (int k = 0; k < info.num_parameters; ++k) {
    // Tolerance: four of the fit's own one-sigma (from the residual noise), and at least 10% of
    // the value for the bias of the replay's discrete approximation of a continuous effect.
    const double tol = std::max(4.0 * got.sigma[k], 0.1 * std::abs(info.typical[k]));
    EXPECT_NEAR(got.value[k], info.typical[k], tol) << info.parameter_names[k];
  }
  const ModelScore true_model =
      ScoreModel(DefaultOmni3Model(), o.true_parameters, {truth}, d.validation);
  std::printf(
      "%s: true %g, fitted %g +- %g; validation CF declared %.5f, with effect %.5f, true model "
      "%.5f\n",
      info.name, info.typical[0], got.value[0], got.sigma[0], r.declared_validation.cf,
      r.final_validation.cf, true_model.cf);
  EXPECT_LE(r.final_validation.cf, 1.15 * true_model.cf)
      << "validation CF " << r.final_validation.cf << " vs true model " << true_model.cf;
  EXPECT_FALSE(r.unexplained_structure);
  ExpectVerdictsMatchTheirTests(r);

  // The calibrated YAML (the model's, as diagnose writes it) carries the effect and the replay
  // honours it when read back.
  const std::string path = ::testing::TempDir() + "/fitcal_diagnose_" + info.name + ".yaml";
  {
    std::ofstream f(path);
    f << model->RobotYaml(r.final_fit.parameters, r.final_fit.effects, "");
  }
  const RobotModelPtr back = ReadRobotModelFile(path);
  ASSERT_EQ(back->robot().effects.size(), 1u);
  const ModelScore replayed =
      ScoreModel(*back, back->robot().nominal, back->robot().effects, d.validation);
  // The YAML keeps 10 significant digits: the CF agrees to far better than its noise.
  EXPECT_NEAR(replayed.cf, r.final_validation.cf, 1e-6 * r.final_validation.cf);
  std::remove(path.c_str());
}

// Every identifiable effect an omni3 robot can show (steering effects need an angle channel:
// tests/tricycle_effects_test.cc; the pivot yaw gain a wheel pair: diff_drive_effects_test.cc).
std::vector<effects::EffectId> IdentifiableEffects() {
  std::vector<effects::EffectId> out;
  for (const auto& info : effects::EffectTable()) {
    if (info.identifiable && !effects::NeedsAngleChannel(info.id) &&
        !effects::NeedsWheelPair(info.id)) {
      out.push_back(info.id);
    }
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(AllLibraryEffects, LibraryEffectTest,
                         ::testing::ValuesIn(IdentifiableEffects()), [](const auto& param) {
                           return std::string(effects::Info(param.param).name);
                         });

// Backlash and acceleration slip, the two start/stop-transient effects (a clock latency stands in
// for part of either: it is significant on such data and must not be named). On a second seed and
// with more repetitions than the sweep above (4: two train, two validate), each is named alone
// and recovered within four of its own sigmas (the fit's covariance, from the noise) - no floor
// on the tolerance; the held-out CF is at most that of the true model plus 15 %.
class TransientEffectTest : public ::testing::TestWithParam<effects::EffectId> {};

TEST_P(TransientEffectTest, IsNamedAndRecoveredWithinFourSigmas) {
  const effects::EffectInfo& info = effects::Info(GetParam());
  sim::FlowerSimulation o = Flower(4, 3);
  const effects::EffectValue truth = InjectTypical(info.id, &o);
  const Data d = Simulate(o, {1, 2});
  const auto model = NominalModel();
  DiagnoseOptions options;
  options.fit.num_threads = 2;
  const DiagnoseResult r = Diagnose(d.training, d.validation, *model, options);
  SCOPED_TRACE(FormatDiagnoseReport(r, *model));
  ASSERT_EQ(r.final_fit.effects.size(), 1u);
  const effects::EffectValue& got = r.final_fit.effects.front();
  EXPECT_EQ(got.id, info.id) << effects::Info(got.id).name;
  EXPECT_TRUE(r.effects_named);
  EXPECT_GT(got.sigma[0], 0.0);
  EXPECT_LT(std::abs(got.value[0] - info.typical[0]), 4.0 * got.sigma[0]);
  const ModelScore true_model =
      ScoreModel(DefaultOmni3Model(), o.true_parameters, {truth}, d.validation);
  std::printf("%s: injected %g, fitted %g +- %g; validation CF %.5f (true model %.5f)\n", info.name,
              info.typical[0], got.value[0], got.sigma[0], r.final_validation.cf, true_model.cf);
  EXPECT_LE(r.final_validation.cf, 1.15 * true_model.cf);
  ExpectVerdictsMatchTheirTests(r);
}

INSTANTIATE_TEST_SUITE_P(StartStopEffects, TransientEffectTest,
                         ::testing::Values(effects::EffectId::kBacklash,
                                           effects::EffectId::kAccelerationSlip),
                         [](const auto& param) {
                           return std::string(effects::Info(param.param).name);
                         });

// Clean data (no injected effect): the tracing must accept nothing. A cheap configuration (12
// of the 36 flower trajectories, 2 repetitions) over 20 seeds; the issue allows at most one false
// positive in 20. Measured: see the printed rate.
TEST(Diagnose, CleanDataAcceptsNoEffectOverTwentySeeds) {
  const auto flower = sim::FlowerTrajectories();
  std::vector<sim::MotionCommand> subset;
  for (std::size_t i = 0; i < flower.size(); i += 3) subset.push_back(flower[i]);
  const auto model = NominalModel();
  int false_positives = 0;
  int structure_false_positives = 0;  // lack of fit or a covariate
  constexpr int kSeeds = 20;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    sim::FlowerSimulation o = Flower(2, static_cast<std::uint64_t>(seed) * 7919);
    o.trajectories = subset;
    o.options.stepped->random_wheel_start_angle =
        true;  // every covariate tested, the absolute wheel angle too
    const Data d = Simulate(o);
    DiagnoseOptions options;
    options.max_effects = 1;  // the first acceptance is the false positive
    const DiagnoseResult r = Diagnose(d.training, d.validation, *model, options);
    if (!r.final_fit.effects.empty()) {
      ++false_positives;
      std::printf("seed %d: false positive %s\n", seed,
                  effects::Info(r.final_fit.effects[0].id).name);
    }
    if (r.unexplained_structure) {
      ++structure_false_positives;
      for (const CovariateTest& t : r.covariates.tests) {
        std::printf("seed %d: covariate %s p = %.2g%s\n", seed, t.name.c_str(), t.p_value,
                    t.significant ? " (significant)" : "");
      }
    }
  }
  std::printf("clean data: %d of %d seeds accepted an effect (false-positive rate %.0f%%)\n",
              false_positives, kSeeds, 100.0 * false_positives / kSeeds);
  std::printf(
      "clean data: %d of %d seeds reported unexplained structure (lack of fit or covariates; "
      "false-positive rate %.0f%%)\n",
      structure_false_positives, kSeeds, 100.0 * structure_false_positives / kSeeds);
  EXPECT_LE(false_positives, 1);
  // Issue 16: at most 5% (one in 20) with the covariate tests added.
  EXPECT_LE(structure_false_positives, 1);
}

// The lack-of-fit test is calibrated where a misweighted statistic shows: clean data with many
// repetitions (10 of the flower, the simulator's default seed). Its 12 components per run are
// strongly correlated; weighing each by its own variance alone read this data set as structure
// (F = 1.39 on (423, 3888) df, p = 8e-7). With the pooled covariance: F = 1.15, p = 0.1.
TEST(Diagnose, LackOfFitIsCalibratedOnCleanDataWithManyRepetitions) {
  sim::FlowerSimulation o = Flower(10, 1);
  const Data d = Simulate(o);
  DiagnoseOptions options;
  options.max_effects = 0;  // the residual of the nine parameters alone
  const DiagnoseResult r = Diagnose(d.training, d.validation, *NominalModel(), options);
  ASSERT_TRUE(r.after.lack_of_fit.available);
  EXPECT_GT(r.after.lack_of_fit.p_value, kLofAlpha) << "F = " << r.after.lack_of_fit.f;
  EXPECT_FALSE(r.unexplained_structure);
}

// A clock latency is named as the cause with many repetitions too (before the start pose was
// taken from a ground-truth sample that shows the robot at rest, interpolating the ground truth
// at t_start + latency blended the rest pose with a moving one and left structure).
TEST(Diagnose, LatencyIsNamedWithManyRepetitions) {
  sim::FlowerSimulation o = Flower(6, 1);
  effects::EffectValue latency;
  latency.id = effects::EffectId::kTimeOffset;
  latency.value[0] = 0.08;
  o.options.stepped->injected_effects = {latency};
  const Data d = Simulate(o);
  const DiagnoseResult r = Diagnose(d.training, d.validation, *NominalModel());
  ASSERT_EQ(r.final_fit.effects.size(), 1u);
  EXPECT_EQ(r.final_fit.effects[0].id, effects::EffectId::kTimeOffset);
  EXPECT_NEAR(r.final_fit.effects[0].value[0], 0.08, 4.0 * r.final_fit.effects[0].sigma[0]);
  EXPECT_TRUE(r.effects_named) << "lack of fit F = " << r.after.lack_of_fit.f
                               << ", p = " << r.after.lack_of_fit.p_value;
}

// An effect outside the library: a turning drift that grows with the time since the motion
// started (omega += k t, e.g. a castor or a roller warming up). No candidate has this shape; the
// tracing must report unexplained structure rather than name the nearest candidate.
TEST(Diagnose, EffectOutsideLibraryIsReportedAsUnexplainedStructure) {
  sim::FlowerSimulation o = Flower(2, 5);
  constexpr double kDriftRadS2 = 0.006;
  o.options.stepped->hook = [](const sim::SteppedState& s, double*, Twist* v, double*) {
    const double* w = s.channel_value;
    if (s.time_since_motion_s >= 0.0 &&
        std::max({std::abs(w[0]), std::abs(w[1]), std::abs(w[2])}) > 0.05) {
      v->omega_rad_s += kDriftRadS2 * s.time_since_motion_s;
    }
  };
  const Data d = Simulate(o);
  const auto model = NominalModel();
  const DiagnoseResult r = Diagnose(d.training, d.validation, *model);
  SCOPED_TRACE(FormatDiagnoseReport(r, *model));
  // A candidate may stand in for part of it (and lower the held-out error), but none is named.
  EXPECT_FALSE(r.effects_named);
  EXPECT_TRUE(r.unexplained_structure);
  EXPECT_LT(r.after.lack_of_fit.p_value, 1e-3);
}

// Encoder clock scale: the nine parameters absorb it exactly (a common radius scale). The
// tracing must say it is not identifiable, accept nothing, and the declared fit must already be
// as good as the true model.
TEST(Diagnose, ClockScaleIsReportedNotIdentifiable) {
  sim::FlowerSimulation o = Flower(2, 9);
  const effects::EffectValue truth = InjectTypical(effects::EffectId::kEncoderClockScale, &o);
  const Data d = Simulate(o);
  const auto model = NominalModel();
  const DiagnoseResult r = Diagnose(d.training, d.validation, *model);
  const std::string report = FormatDiagnoseReport(r, *model);
  SCOPED_TRACE(report);
  EXPECT_TRUE(r.final_fit.effects.empty());
  EXPECT_NE(report.find("encoder_clock_scale: not identifiable"), std::string::npos);
  // The numerical check agrees with the registry: nothing of its column is separable.
  EXPECT_LT(SeparableFraction(d.training, *model, r.base.parameters, {}, truth.id), 1e-6);
  const ModelScore true_model =
      ScoreModel(DefaultOmni3Model(), o.true_parameters, {truth}, d.validation);
  EXPECT_LE(r.declared_validation.cf, 1.15 * true_model.cf);
  // The radii absorb the scale: r_i(fitted) ~ r_i(true) (1 + s).
  for (int i = 0; i < 3; ++i) {
    const double expected = sim::PalacinTable5Parameters().radius_m[i] * (1.0 + truth.value[0]);
    EXPECT_NEAR(r.declared.parameters[omni3::kRadiusIndex + i], expected, 0.003 * expected);
  }
}

// What to record next. On straight runs only (R1-R12, no rotation) a
// yaw-rate slip has no influence at all: the tracing must say it cannot be told apart and name
// the runs that would separate it, rather than fit it.
TEST(Diagnose, SaysWhichRunsWouldSeparateAnUnidentifiableCandidate) {
  const auto flower = sim::FlowerTrajectories();
  sim::FlowerSimulation o = Flower(2, 21);
  o.trajectories.assign(flower.begin(), flower.begin() + 12);  // R1..R12
  const Data d = Simulate(o);
  DiagnoseOptions options;
  options.candidates = {effects::EffectId::kYawRateSlip, effects::EffectId::kWheelSpeedSlip};
  const auto model = NominalModel();
  const DiagnoseResult r = Diagnose(d.training, d.validation, *model, options);
  const std::string report = FormatDiagnoseReport(r, *model);
  SCOPED_TRACE(report);
  EXPECT_TRUE(r.final_fit.effects.empty());
  EXPECT_NE(report.find("yaw_rate_slip cannot be told apart"), std::string::npos);
  EXPECT_NE(report.find(effects::Info(effects::EffectId::kYawRateSlip).separating_runs),
            std::string::npos);
}

// A speed-dependent slip partly trades off with the radii when every run has the same speed;
// the flower at a second speed (FlowerTrajectories(speed)) separates it. Same number of runs
// (72) either way: two repetitions of one flower, or one of each speed; the part of the slip's
// influence that the nine parameters cannot mimic must grow clearly (measured: printed).
TEST(Diagnose, SecondSpeedFlowerSeparatesSpeedSlip) {
  const auto unexplained = [](std::vector<sim::MotionCommand> trajectories, int repetitions) {
    sim::FlowerSimulation o = Flower(repetitions, 4);
    o.trajectories = std::move(trajectories);
    const Data d = Simulate(o);
    std::vector<TrackRun> all = d.training;
    all.insert(all.end(), d.validation.begin(), d.validation.end());
    double norm = 0.0;
    SeparableFraction(all, DefaultOmni3Model(), o.true_parameters, {},
                      effects::EffectId::kWheelSpeedSlip, {}, &norm);
    return norm;
  };
  const double one_speed = unexplained(sim::FlowerTrajectories(0.35), 2);
  auto two = sim::FlowerTrajectories(0.35);
  const auto fast = sim::FlowerTrajectories(0.6, 0.6);
  two.insert(two.end(), fast.begin(), fast.end());
  const double two_speeds = unexplained(two, 1);
  std::printf("speed slip: unexplained influence |(I-P)J|: one speed %.4g, two speeds %.4g\n",
              one_speed, two_speeds);
  EXPECT_GT(two_speeds, 1.5 * one_speed);
}

}  // namespace
}  // namespace fitcal
