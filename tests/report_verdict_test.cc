// The report's verdict (validation/verdict.h) on crafted cases, the repetition noise-floor test,
// the relative pose error (validation/relative_pose_error.h) against closed forms, and which runs
// of a data set trained a calibration (validation/training_runs.h).

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "validation/relative_pose_error.h"
#include "validation/training_runs.h"
#include "validation/verdict.h"

namespace fitcal {
namespace {

GroupOutcome Group(const std::string& name, double cf_before, double cf_after,
                   double position_before_m, double position_after_m) {
  return {name, 5, cf_before, cf_after, position_before_m, position_after_m};
}

// A calibration that helps everywhere, converged, inside its box, identifiable: PASS.
VerdictInputs GoodCase() {
  VerdictInputs in;
  in.termination = "CONVERGENCE";
  in.overall = Group("all validation runs", 0.07, 0.008, 0.048, 0.005);
  in.families = {Group("R", 0.05, 0.006, 0.04, 0.004), Group("G", 0.08, 0.009, 0.05, 0.006)};
  in.trajectories = {Group("R1", 0.05, 0.006, 0.04, 0.004), Group("G1", 0.08, 0.009, 0.05, 0.006)};
  in.has_training_cf = true;
  in.training_cf_after = 0.0075;
  in.identifiability_checked = true;
  in.identifiable = true;
  return in;
}

const VerdictReason* Find(const Verdict& v, const std::string& check) {
  for (const VerdictReason& r : v.reasons) {
    if (r.check == check) return &r;
  }
  return nullptr;
}

TEST(VerdictTest, GoodCalibrationPasses) {
  const Verdict v = JudgeCalibration(GoodCase());
  EXPECT_EQ(v.level, VerdictLevel::kPass);
  for (const VerdictReason& r : v.reasons) {
    // GoodCase has no repeated trajectory: the noise floor is not measured (SKIP, issue 42).
    const VerdictLevel expected = r.check == "noise_floor" ? VerdictLevel::kSkip : VerdictLevel::kPass;
    EXPECT_EQ(r.level, expected) << r.check << ": " << r.message;
    EXPECT_FALSE(r.section.empty()) << r.check;
  }
  ASSERT_NE(Find(v, "improvement"), nullptr);
  EXPECT_NE(Find(v, "improvement")->message.find("0.0700 -> 0.0080"), std::string::npos);
}

// Issue 42: "... (74 % lower) on 1 runs" on the README's one free run.
TEST(VerdictTest, TheRunCountAgreesWithItsNoun) {
  VerdictInputs in = GoodCase();
  in.overall.runs = 1;
  EXPECT_NE(Find(JudgeCalibration(in), "improvement")->message.find("lower) on 1 run"),
            std::string::npos);
  EXPECT_EQ(Find(JudgeCalibration(in), "improvement")->message.find("1 runs"), std::string::npos);
  in.overall.runs = 2;
  EXPECT_NE(Find(JudgeCalibration(in), "improvement")->message.find("lower) on 2 runs"),
            std::string::npos);
}

TEST(VerdictTest, ParameterOnABoundWarns) {
  VerdictInputs in = GoodCase();
  in.at_bound = {"R_a"};
  const Verdict v = JudgeCalibration(in);
  EXPECT_EQ(v.level, VerdictLevel::kWarn);
  ASSERT_NE(Find(v, "bounds"), nullptr);
  EXPECT_EQ(Find(v, "bounds")->level, VerdictLevel::kWarn);
  EXPECT_NE(Find(v, "bounds")->message.find("R_a"), std::string::npos);
  EXPECT_EQ(v.reasons.front().check, "bounds");  // worst first
}

// The issue's case: overall better, one square session's final position 68 -> 102 mm.
TEST(VerdictTest, OneTrajectoryWorseWarnsAndNamesIt) {
  VerdictInputs in = GoodCase();
  in.trajectories.push_back(Group("square_231220200510", 0.09, 0.08, 0.068, 0.102));
  const Verdict v = JudgeCalibration(in);
  EXPECT_EQ(v.level, VerdictLevel::kWarn);
  const VerdictReason* r = Find(v, "regressions");
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->level, VerdictLevel::kWarn);
  EXPECT_NE(r->message.find("square_231220200510"), std::string::npos) << r->message;
  EXPECT_NE(r->message.find("68 -> 102 mm"), std::string::npos) << r->message;
  // A family whose CF gets worse is a regression too.
  in = GoodCase();
  in.families[1].cf_after = 0.085;  // +6 %
  EXPECT_EQ(JudgeCalibration(in).level, VerdictLevel::kWarn);
  // Within kRegressionTolerance (5 %) is not a regression: 68 -> 71 mm (+4.4 %) is let through,
  // 68 -> 102 mm is not.
  in = GoodCase();
  in.trajectories.push_back(Group("square_a", 0.09, 0.085, 0.068, 0.071));
  EXPECT_EQ(Find(JudgeCalibration(in), "regressions")->level, VerdictLevel::kPass);
  in.trajectories.push_back(Group("square_b", 0.09, 0.08, 0.068, 0.102));
  const Verdict v2 = JudgeCalibration(in);
  const VerdictReason* r2 = Find(v2, "regressions");
  ASSERT_NE(r2, nullptr);
  EXPECT_EQ(r2->level, VerdictLevel::kWarn);
  EXPECT_EQ(r2->message.find("square_a"), std::string::npos) << r2->message;
  EXPECT_NE(r2->message.find("square_b"), std::string::npos) << r2->message;
}

TEST(VerdictTest, NoHeldOutImprovementFails) {
  VerdictInputs in = GoodCase();
  in.overall.cf_after = in.overall.cf_before;  // equal is no improvement
  Verdict v = JudgeCalibration(in);
  EXPECT_EQ(v.level, VerdictLevel::kFail);
  EXPECT_EQ(v.reasons.front().check, "improvement");
  in.overall.cf_after = 1.5 * in.overall.cf_before;
  EXPECT_EQ(JudgeCalibration(in).level, VerdictLevel::kFail);
}

// Issue 42: a copy of the diff drive's calibration with wheel_separation_m 0.215 judged on its 20
// held-out runs printed "no improvement on the 1488919704 held-out runs: CF 20.0000 with the
// calibration, 0.6691 with the nominal" (an int formatted as a double). The numbers of the message
// are the inputs, each in its place.
TEST(VerdictTest, NoImprovementMessageQuotesTheRightNumbers) {
  VerdictInputs in = GoodCase();
  in.overall.runs = 20;
  in.overall.cf_before = 0.1366;
  in.overall.cf_after = 0.6691;
  const Verdict v = JudgeCalibration(in);
  const VerdictReason* r = Find(v, "improvement");
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->level, VerdictLevel::kFail);
  EXPECT_EQ(r->message,
            "no improvement on the 20 held-out runs: CF 0.6691 with the calibration, 0.1366 with "
            "the nominal");
  // The nominal passed as its own calibration: equal CFs, the same message with its numbers.
  in.overall.runs = 1;
  in.overall.cf_after = in.overall.cf_before;
  EXPECT_EQ(Find(Verdict(JudgeCalibration(in)), "improvement")->message,
            "no improvement on the 1 held-out runs: CF 0.1366 with the calibration, 0.1366 with "
            "the nominal");
}

// A check that could not run is SKIP, not PASS, and leaves the overall level alone (issue 42:
// "PASS noise_floor: ... the noise floor is not measured").
TEST(VerdictTest, NoiseFloorNotMeasuredIsSkippedNotPassed) {
  VerdictInputs in = GoodCase();
  in.noise_floor = NoiseFloorTest{};  // no trajectory with two validation runs
  const Verdict v = JudgeCalibration(in);
  const VerdictReason* r = Find(v, "noise_floor");
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->level, VerdictLevel::kSkip);
  EXPECT_STREQ(ToString(r->level), "SKIP");
  EXPECT_NE(r->message.find("not measured"), std::string::npos) << r->message;
  EXPECT_EQ(v.level, VerdictLevel::kPass);
  EXPECT_EQ(v.reasons.back().check, "noise_floor");  // after every check that ran
}

// Held-out runs too short for any drift window left an empty table and "drift": [] without a
// word; the verdict says so as a SKIP with the longest run's path, and only then.
TEST(VerdictTest, DriftNotMeasuredIsSkippedWithTheLongestPath) {
  VerdictInputs in = GoodCase();
  EXPECT_EQ(Find(JudgeCalibration(in), "drift"), nullptr);
  in.drift_measured = false;
  in.longest_path_m = 0.31;
  const Verdict v = JudgeCalibration(in);
  const VerdictReason* r = Find(v, "drift");
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->level, VerdictLevel::kSkip);
  EXPECT_EQ(r->section, "drift");
  EXPECT_NE(r->message.find("not measured: the held-out runs are too short for its windows (the "
                            "longest travels 0.31 m of ground-truth path)"),
            std::string::npos)
      << r->message;
  EXPECT_EQ(v.level, VerdictLevel::kPass);
}

TEST(VerdictTest, ConvergenceGapAndIdentifiability) {
  VerdictInputs in = GoodCase();
  in.termination = "NO_CONVERGENCE";
  EXPECT_EQ(JudgeCalibration(in).level, VerdictLevel::kWarn);
  in.termination = "FAILURE";
  EXPECT_EQ(JudgeCalibration(in).level, VerdictLevel::kFail);
  in.termination = "MAXEVAL_REACHED";  // a global NLopt method's normal end
  EXPECT_EQ(JudgeCalibration(in).level, VerdictLevel::kPass);
  in.termination.clear();  // a plain robot YAML: nothing recorded, no finding
  EXPECT_EQ(Find(JudgeCalibration(in), "convergence"), nullptr);

  in = GoodCase();
  in.training_cf_after = in.overall.cf_after / (kGapFactor + 0.01);
  EXPECT_EQ(Find(JudgeCalibration(in), "generalisation")->level, VerdictLevel::kWarn);
  in.training_cf_after = in.overall.cf_after / (kGapFactor - 0.01);
  EXPECT_EQ(Find(JudgeCalibration(in), "generalisation")->level, VerdictLevel::kPass);

  in = GoodCase();
  in.identifiable = false;
  EXPECT_EQ(Find(JudgeCalibration(in), "identifiability")->level, VerdictLevel::kWarn);
  in.identifiability_checked = false;  // training runs in another data set: not judged
  EXPECT_EQ(Find(JudgeCalibration(in), "identifiability"), nullptr);
  EXPECT_EQ(JudgeCalibration(in).level, VerdictLevel::kPass);
}

// 20 trajectories x 5 repetitions of pure noise (sigma 5 mm per axis, seeded): the F test finds
// nothing (p far above 1e-3 for this seed) and estimates sigma within 15 % (its relative standard
// error is 1/sqrt(2 dof) = 1/sqrt(320) = 5.6 %; 15 % is 2.7 of those). A 20 mm bias per trajectory
// (4 sigma, 2.8x one run's noise) is flagged.
TEST(VerdictTest, NoiseFloorTestSeesASystematicResidual) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.005);
  std::vector<FinalErrorSample> pure, biased;
  for (int t = 0; t < 20; ++t) {
    const double bx = 0.02 * std::cos(t), by = 0.02 * std::sin(t);
    for (int rep = 0; rep < 5; ++rep) {
      const double ex = noise(rng), ey = noise(rng);
      pure.push_back({"T" + std::to_string(t), ex, ey});
      biased.push_back({"T" + std::to_string(t), ex + bx, ey + by});
    }
  }
  const NoiseFloorTest a = TestAgainstNoiseFloor(pure);
  ASSERT_TRUE(a.available);
  EXPECT_NEAR(a.noise_sigma_m, 0.005, 0.15 * 0.005);
  EXPECT_GT(a.p_value, 1e-2);
  VerdictInputs in = GoodCase();
  in.noise_floor = a;
  EXPECT_EQ(Find(JudgeCalibration(in), "noise_floor")->level, VerdictLevel::kPass);

  const NoiseFloorTest b = TestAgainstNoiseFloor(biased);
  EXPECT_NEAR(b.noise_sigma_m, a.noise_sigma_m, 1e-12);  // a bias does not change the scatter
  EXPECT_LT(b.p_value, 1e-12);
  EXPECT_NEAR(b.systematic_rms_m, 0.02, 0.004);
  in.noise_floor = b;
  EXPECT_EQ(Find(JudgeCalibration(in), "noise_floor")->level, VerdictLevel::kWarn);
  EXPECT_EQ(JudgeCalibration(in).level, VerdictLevel::kWarn);

  // Significant (p = 3e-5, as seen on a real robot) but smaller than one run's own noise: PASS,
  // and the message says the residual is detectable, never "at the noise floor" beside a tiny p.
  NoiseFloorTest small = a;
  small.p_value = 3e-5;
  small.systematic_rms_m = 1.2 * small.noise_sigma_m;
  in.noise_floor = small;
  const VerdictReason* r = Find(JudgeCalibration(in), "noise_floor");
  EXPECT_EQ(r->level, VerdictLevel::kPass);
  EXPECT_EQ(r->message.find("at the noise floor"), std::string::npos) << r->message;
  EXPECT_NE(r->message.find("detectable"), std::string::npos) << r->message;
  EXPECT_NE(r->message.find("p = 3e-05"), std::string::npos) << r->message;

  // One run per trajectory: no scatter to compare with.
  EXPECT_FALSE(TestAgainstNoiseFloor({{"A", 0.01, 0.0}, {"B", 0.0, 0.01}}).available);
}

// A straight drive of 10 m whose odometry reads 2 % long: every 1 m window has a 2 % translation
// error and no rotation error; an odometry turning 1 deg per metre too much along a straight line
// has a rotation error of 1 deg/m (to first order in the window's small angles).
TEST(RelativePoseErrorTest, StraightDriveClosedForms) {
  std::vector<Pose2d> truth, long_odometry, turning;
  for (int k = 0; k <= 40; ++k) {
    const double s = 0.25 * k;  // exact in binary: every 1 m window is exactly 4 steps
    truth.push_back({s, 0.0, 0.3});
    long_odometry.push_back({1.02 * s, 0.0, 0.3});
    turning.push_back({s, 0.0, 0.3 + s * M_PI / 180.0});
  }
  const RelativePoseErrorTruth truth_side(truth);
  RelativePoseErrorSum a, b;
  RelativePoseErrorRun(truth_side, long_odometry).Add(1.0, &a);
  EXPECT_EQ(a.windows, 41 - 4);
  EXPECT_NEAR(a.MeanTranslationPercent(), 2.0, 1e-9);
  EXPECT_NEAR(a.MeanRotationRadPerM(), 0.0, 1e-12);
  RelativePoseErrorRun(truth_side, turning).Add(1.0, &b);
  EXPECT_NEAR(b.MeanRotationRadPerM(), M_PI / 180.0, 1e-9);
  RelativePoseErrorSum none;
  RelativePoseErrorRun(truth_side, long_odometry).Add(20.0, &none);  // longer than the run
  EXPECT_EQ(none.windows, 0);
  EXPECT_EQ(RelativePoseErrorLengths(5.0), (std::vector<double>{0.5, 1.0, 2.0}));
  EXPECT_EQ(RelativePoseErrorLengths(0.4), (std::vector<double>{}));
}

RunLog Log(const std::string& id, int repetition, double rate) {
  RunLog log;
  log.id = id;
  log.trajectory = id.substr(0, 2);
  log.repetition = repetition;
  for (int k = 0; k < 5; ++k) {
    log.encoders.t_s.push_back(0.1 * k);
    if (k > 0) log.encoders.samples.push_back(0.1, {rate, -rate, 0.5 * rate});
  }
  log.ground_truth.t_s = {0.0, 0.4};
  log.ground_truth.world_T_robot = {Pose2d{}, Pose2d{0.1, 0.0, 0.0}};
  return log;
}

std::vector<AlignedRun> Aligned(const std::vector<RunLog>& logs) { return AlignRuns(logs); }

// The training runs are found by id only on the data set that trained the calibration: the same
// ids with other encoder data (another simulator seed) make every run validate.
TEST(TrainingRunsTest, RecordedRunsTrainOnlyOnTheirOwnDataSet) {
  const std::vector<RunLog> mine = {Log("R1-rep01", 1, 1.0), Log("R1-rep02", 2, 1.1),
                                    Log("G1-rep01", 1, 1.2)};
  const std::vector<RunLog> other = {Log("R1-rep01", 1, 2.0), Log("R1-rep02", 2, 2.1),
                                     Log("G1-rep01", 1, 2.2)};
  RecordedTraining recorded;
  recorded.run_ids = {"R1-rep01", "G1-rep01"};
  recorded.fingerprint = TrainingFingerprint(mine, recorded.run_ids);
  EXPECT_EQ(recorded.fingerprint.size(), 16u);
  EXPECT_NE(recorded.fingerprint, TrainingFingerprint(other, recorded.run_ids));
  EXPECT_EQ(recorded.fingerprint, TrainingFingerprint(mine, {"G1-rep01", "R1-rep01"}));

  const TrainingSplit same = SplitAsRecorded(mine, Aligned(mine), recorded);
  EXPECT_EQ(same.how, "by id");
  ASSERT_EQ(same.split.validation.size(), 1u);
  EXPECT_EQ(same.split.validation[0].id, "R1-rep02");
  EXPECT_EQ(same.split.training.size(), 2u);

  const TrainingSplit another = SplitAsRecorded(other, Aligned(other), recorded);
  EXPECT_EQ(another.how, "none");
  EXPECT_EQ(another.split.validation.size(), 3u);
  EXPECT_TRUE(another.split.training.empty());

  // Nothing recorded (a plain robot YAML): every run validates. Repetitions only (an older
  // file): by repetition.
  EXPECT_EQ(SplitAsRecorded(mine, Aligned(mine), {}).split.validation.size(), 3u);
  RecordedTraining old;
  old.repetitions = {1};
  const TrainingSplit by_rep = SplitAsRecorded(mine, Aligned(mine), old);
  EXPECT_EQ(by_rep.how, "by repetition");
  EXPECT_EQ(by_rep.split.validation.size(), 1u);
}

}  // namespace
}  // namespace fitcal
