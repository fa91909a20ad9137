// Calibrate(request) -> CalibrationOutcome (calibrate/calibrate.h) called as a library, without
// the command: the refusals come back with their exit code, reason and stage, nothing is left to
// the caller to decide, and the selected candidate is the gate's on the runs it says it judged
// on. The CFs the outcome reports are checked against a replay of the selected parameters made
// here (fit/final_pose_errors.h), not against the outcome's own numbers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "calibrate/calibrate.h"
#include "calibrate/diagnosis_calibration.h"
#include "calibrate/method_comparison.h"
#include "fit/final_pose_errors.h"
#include "fit/run_split.h"
#include "io/dataset.h"
#include "models/model_registry.h"
#include "tests/test_paths.h"

namespace fitcal {
namespace {

struct Loaded {
  RobotModelPtr model;
  CalibrationRequest request;
};

// The shipped data set `name` loaded with its robot's channels, fitted on final poses by Ceres
// (the command's defaults otherwise: fixed weights of 1 m and 1 rad).
Loaded Load(const std::string& name) {
  const std::string dir = FITCAL_SOURCE_DIR + "/data/" + name;
  const io::DatasetIndex index = io::ReadDatasetIndex(dir);
  Loaded out{ReadRobotModelFile(index.robot_path), {}};
  CalibrationRequest& r = out.request;
  r.dataset = dir;
  r.method = FindFitMethod("ceres");
  r.settings.threads = 2;
  r.settings.estimate_weights = false;
  r.settings.residuals = ResidualKind::kFinalPose;
  r.runs = io::LoadDataset(index, out.model->robot()).runs;
  r.threads = 2;
  return out;
}

TEST(Calibrate, ATrainingSelectionThatMatchesNoRunIsRefusedWithUsageExitBeforeAnyFit) {
  Loaded l = Load("flower");
  l.request.train_reps = "40-50";
  const CalibrationOutcome o = Calibrate(l.request, *l.model);
  EXPECT_EQ(o.exit_code(), 2);
  EXPECT_EQ(o.reached, CalibrationStage::kChecks);
  ASSERT_EQ(o.refusal.reasons.size(), 1u);
  EXPECT_EQ(o.refusal.reasons[0], "no run of " + l.request.dataset +
                                      " is a training run (repetitions 40-50)");
  EXPECT_TRUE(o.candidates.empty());
  EXPECT_FALSE(o.record.has_value());
}

TEST(Calibrate, TrackResidualsWithAMethodThatFitsFinalPosesOnlyAreRefusedWithUsageExit) {
  Loaded l = Load("flower");
  l.request.method = FindFitMethod("sbplx");
  l.request.settings.residuals = ResidualKind::kTrack;
  const CalibrationOutcome o = Calibrate(l.request, *l.model);
  EXPECT_EQ(o.exit_code(), 2);
  ASSERT_EQ(o.refusal.reasons.size(), 1u);
  EXPECT_EQ(o.refusal.reasons[0],
            "--residuals track needs a Ceres method (--method ceres or ceres-dogleg); sbplx fits "
            "final poses only");
}

TEST(Calibrate, TheSelectedCandidateIsTheLowestHeldOutCfAndItsRecordSaysSo) {
  Loaded l = Load("flower");
  const CalibrationOutcome o = Calibrate(l.request, *l.model);
  ASSERT_EQ(o.exit_code(), 0);
  EXPECT_EQ(o.reached, CalibrationStage::kDone);
  ASSERT_FALSE(o.split.validation.empty());
  ASSERT_TRUE(o.record.has_value());
  EXPECT_EQ(o.candidates[0].name, "nominal");
  EXPECT_EQ(o.record->selected, o.selected().name);
  // The held-out CF of every candidate, replayed here; the selected one is the lowest, strictly
  // below the nominal's, and the record's before/after are the nominal's and the selected one's.
  std::vector<double> cf;
  for (const CalibrationCandidate& c : o.candidates) {
    cf.push_back(EvaluateFinalPoseErrors(*l.model, c.parameters, o.split.validation, 1).cf);
  }
  const auto lowest = std::min_element(cf.begin(), cf.end()) - cf.begin();
  EXPECT_EQ(o.gate.selected, lowest);
  EXPECT_LT(cf[o.gate.selected], cf[0]);
  // Sums over runs in another thread order: equal to rounding.
  EXPECT_NEAR(o.record->cf_validation_before, cf[0], 1e-12);
  EXPECT_NEAR(o.record->cf_validation_after, cf[o.gate.selected], 1e-12);
  EXPECT_TRUE(o.record->has_uncertainty);
}

TEST(Calibrate, ARequestThatDoesNotWriteGetsNoRecord) {
  Loaded l = Load("flower");
  l.request.will_write = false;
  const CalibrationOutcome o = Calibrate(l.request, *l.model);
  EXPECT_EQ(o.exit_code(), 0);
  EXPECT_EQ(o.reached, CalibrationStage::kDone);
  EXPECT_FALSE(o.record.has_value());
}

// data/undeclared_effect: a robot with an effect its model lacks; the fit pushes a radius onto
// its bound. Refused at that stage (exit 5) unless the bounds were widened on purpose, when the
// refusal becomes the warning and the record is made.
TEST(Calibrate, AParameterOnItsBoundRefusesUnlessTheBoundsWereWidened) {
  Loaded l = Load("undeclared_effect");
  const CalibrationOutcome refused = Calibrate(l.request, *l.model);
  EXPECT_EQ(refused.exit_code(), 5);
  EXPECT_EQ(refused.reached, CalibrationStage::kAtBound);
  ASSERT_EQ(refused.refusal.reasons.size(), 1u);
  const std::string& reason = refused.refusal.reasons[0];
  EXPECT_EQ(reason.rfind("'ceres' leaves a parameter on its bound (", 0), 0u) << reason;
  EXPECT_FALSE(refused.record.has_value());

  l.request.bounds_widened = true;
  const CalibrationOutcome widened = Calibrate(l.request, *l.model);
  EXPECT_EQ(widened.exit_code(), 0);
  EXPECT_EQ(widened.reached, CalibrationStage::kDone);
  EXPECT_EQ(widened.at_bound_warning + "; nothing written", reason);
  EXPECT_TRUE(widened.record.has_value());
}

// CalibrateOnDiagnosis (calibrate/diagnosis_calibration.h) on diagnoses made up here: every fit
// at the nominal ties with it, and the nominal wins ties (exit 5, nothing to write); a track fit
// with the parameters a Ceres fit of the flower found, without a covariance of its own, is
// selected, gets the uncertainty propagated through the training runs and is recorded.
struct DiagnosisCase {
  Loaded loaded = Load("flower");
  SplitOf<TrackRun> split;
  DiagnoseResult result;
  DiagnosisCase() {
    const Robot& robot = loaded.model->robot();
    split = SplitForFit(PrepareTrackRuns(loaded.request.runs, WheelChannelMask(robot)), "1-5", "");
    result.declared.parameters = robot.nominal;
    result.declared.usable = true;
    result.declared_validation.cf = 1e9;  // worse than anything: never selected
    result.base.parameters = robot.nominal;
  }
  DiagnosisCalibration Run() const {
    return CalibrateOnDiagnosis({"flower", "", &loaded.request.runs, 2}, *loaded.model, split,
                                result);
  }
};

TEST(CalibrateOnDiagnosis, TheNominalWinsTiesAndIsRefusedWithExitFive) {
  const DiagnosisCase c;
  const DiagnosisCalibration d = c.Run();
  EXPECT_EQ(d.refusal.exit_code, 5);
  EXPECT_EQ(d.reached, CalibrationStage::kGate);
  ASSERT_EQ(d.gate.size(), 3u);
  EXPECT_EQ(d.gate[2].cf_after, d.gate[0].cf_after);  // the track fit at the nominal: a tie
  EXPECT_EQ(d.choice.name, "nominal");
}

TEST(CalibrateOnDiagnosis, ATrackFitWithoutCovarianceGetsThePropagatedUncertaintyAndIsRecorded) {
  DiagnosisCase c;
  const CalibrationOutcome fit = Calibrate(c.loaded.request, *c.loaded.model);
  ASSERT_EQ(fit.exit_code(), 0);
  c.result.base.parameters = fit.selected().parameters;
  const DiagnosisCalibration d = c.Run();
  ASSERT_EQ(d.refusal.exit_code, 0) << d.refusal.reasons.front();
  EXPECT_EQ(d.reached, CalibrationStage::kDone);
  EXPECT_EQ(d.choice.name, "track fit");
  EXPECT_LT(d.choice.cf_after, d.gate[0].cf_after);
  EXPECT_TRUE(d.uncertainty_propagated);
  EXPECT_EQ(d.record.selected, "track fit");
  EXPECT_TRUE(d.record.has_uncertainty);
  ASSERT_EQ(d.record.sigma.size(), c.loaded.model->robot().nominal.size());
  for (double sigma : d.record.sigma) EXPECT_GT(sigma, 0.0);
  EXPECT_EQ(d.record.cf_validation_after, d.choice.cf_after);
}

// fit's bounds' rule in diagnose: the declared fit, said to be the lowest on the held-out runs
// but with its first parameter on its upper bound, gives way to the track fit (the flower's fit,
// inside its bounds, beating the nominal), and a line says why; with the track fit on its bound
// too, nothing beats the nominal inside its bounds: exit 5, the bound named.
TEST(CalibrateOnDiagnosis, ACandidateOnItsBoundGivesWayOrIsRefused) {
  DiagnosisCase c;
  const CalibrationOutcome fit = Calibrate(c.loaded.request, *c.loaded.model);
  ASSERT_EQ(fit.exit_code(), 0);
  const Robot& robot = c.loaded.model->robot();
  std::vector<double> on_bound = fit.selected().parameters;
  on_bound[0] = robot.bounds[0].hi;
  c.result.declared.parameters = on_bound;
  c.result.declared_validation.cf = 0.0;  // the lowest of all
  c.result.base.parameters = fit.selected().parameters;
  const DiagnosisCalibration gave_way = c.Run();
  ASSERT_EQ(gave_way.refusal.exit_code, 0) << gave_way.refusal.reasons.front();
  EXPECT_EQ(gave_way.choice.name, "track fit");
  EXPECT_EQ(gave_way.gave_way_line.rfind("'declared final-pose fit' leaves a parameter on its "
                                         "bound (" + robot.parameters[0].name + " ", 0),
            0u)
      << gave_way.gave_way_line;

  c.result.base.parameters = on_bound;
  const DiagnosisCalibration refused = c.Run();
  EXPECT_EQ(refused.refusal.exit_code, 5);
  EXPECT_EQ(refused.choice.name, "nominal");
  ASSERT_EQ(refused.refusal.reasons.size(), 1u);
  EXPECT_EQ(refused.refusal.reasons[0].rfind("'declared final-pose fit' leaves a parameter on", 0),
            0u)
      << refused.refusal.reasons[0];
}

// A declared fit that stopped short of converging (a finite point, not usable) is no candidate,
// however low its held-out CF, and a line says so; the track fit is written. Without even a
// finite point, or with a track fit that did not converge, the diagnosis is refused (exit 3).
TEST(CalibrateOnDiagnosis, ADeclaredFitThatDidNotConvergeIsNoCandidate) {
  DiagnosisCase c;
  const CalibrationOutcome fit = Calibrate(c.loaded.request, *c.loaded.model);
  ASSERT_EQ(fit.exit_code(), 0);
  c.result.declared.usable = false;
  c.result.declared.stopped_early = true;
  c.result.declared.termination = "NO_CONVERGENCE";
  c.result.declared_validation.cf = 0.0;  // the lowest of all, were it a candidate
  c.result.base.parameters = fit.selected().parameters;
  c.result.final_fit.usable = true;
  const DiagnosisCalibration d = c.Run();
  ASSERT_EQ(d.refusal.exit_code, 0) << d.refusal.reasons.front();
  ASSERT_EQ(d.gate.size(), 2u);
  EXPECT_EQ(d.gate[1].name, "track fit");
  EXPECT_EQ(d.choice.name, "track fit");
  EXPECT_EQ(d.left_out_line,
            "declared final-pose fit: not a candidate, it did not converge (NO_CONVERGENCE)");
  EXPECT_EQ(RefusalOfUnconvergedFits(c.result).exit_code, 0);

  c.result.declared.stopped_early = false;
  EXPECT_EQ(RefusalOfUnconvergedFits(c.result).exit_code, 3);
  c.result.declared.usable = true;
  c.result.final_fit.usable = false;
  c.result.final_fit.termination = "NO_CONVERGENCE";
  const Refusal track = RefusalOfUnconvergedFits(c.result);
  EXPECT_EQ(track.exit_code, 3);
  EXPECT_EQ(track.reasons.at(0),
            "the track fit did not converge (NO_CONVERGENCE); nothing written");
}

// CompareMethods (calibrate/method_comparison.h, `fitcal compare` without the command): one
// strategy (STB: curves both ways; STA's three straight runs do not determine the wheels'
// angles, and their fit is worse held out, as in Palacin Table 4), Ceres on the first repetition
// of the flower.
ComparisonRequest FlowerComparison() {
  const Loaded l = Load("flower");
  ComparisonRequest r;
  r.data_name = "data/flower";
  r.model = l.model;
  r.runs = AlignRuns(l.request.runs);
  r.methods = {FindFitMethod("ceres")};
  r.strategies = {ParseCompareStrategy("STB")};
  r.counts = {1};
  r.settings = l.request.settings;
  r.threads = 2;
  return r;
}

// The rows' CFs replayed here on the runs the comparison says it used: repetition 1 of STB's six
// curves to train, every run of repetitions 2-10 to validate; the simulated flower's truth (Palacin
// Table 5) is far from the nominal, so the fit must improve the held-out CF.
TEST(CompareMethods, RowsAreTheReplayOfTheirParametersOnTheTrainingAndHeldOutRuns) {
  const ComparisonRequest r = FlowerComparison();
  const MethodComparison c = CompareMethods(r);
  ASSERT_TRUE(c.refusal.empty()) << c.refusal;
  EXPECT_EQ(c.validation_reps, (std::vector<int>{2, 3, 4, 5, 6, 7, 8, 9, 10}));
  const std::vector<AlignedRun> held_out = SplitByRepetition(r.runs, c.validation_reps).training;
  ASSERT_EQ(c.num_validation, 9u * 36u);
  ASSERT_EQ(held_out.size(), c.num_validation);
  const std::vector<AlignedRun> training = SelectRuns(r.runs, r.strategies[0], {1});
  ASSERT_EQ(training.size(), 6u);
  ASSERT_EQ(c.rows.size(), 2u);
  const ComparisonRow& none = c.rows[0];
  const ComparisonRow& ceres = c.rows[1];
  EXPECT_EQ(none.method, "None");
  EXPECT_DOUBLE_EQ(none.cf_validation,
                   EvaluateFinalPoseErrors(*r.model, r.model->robot().nominal, held_out).cf);
  EXPECT_EQ(ceres.strategy, "STB");
  EXPECT_EQ(ceres.method, "ceres");
  EXPECT_EQ(ceres.repetitions, 1);
  EXPECT_DOUBLE_EQ(ceres.cf_calibration,
                   EvaluateFinalPoseErrors(*r.model, ceres.parameters, training).cf);
  EXPECT_DOUBLE_EQ(ceres.cf_validation,
                   EvaluateFinalPoseErrors(*r.model, ceres.parameters, held_out).cf);
  EXPECT_LT(ceres.cf_validation, none.cf_validation);
  EXPECT_NEAR(ceres.improvement_percent,
              100.0 * (none.cf_validation - ceres.cf_validation) / none.cf_validation, 1e-9);
}

TEST(CompareMethods, AValidationRepetitionThatTrainsIsRefusedBeforeAnyFit) {
  ComparisonRequest r = FlowerComparison();
  r.validation_reps = {1, 6};
  const MethodComparison c = CompareMethods(r);
  EXPECT_EQ(c.refusal, "validation repetition 1 is also a training repetition");
  EXPECT_TRUE(c.rows.empty());
}

// Without --strategies, a data set without the flower's labels trains on every trajectory ("all"),
// whatever the model (omni3 took STA..STE and was refused before the one loader).
TEST(CompareMethods, WithoutTheFlowersLabelsTheDefaultStrategiesBecomeAll) {
  ComparisonRequest r = FlowerComparison();
  for (AlignedRun& run : r.runs) run.trajectory = "loop/" + run.trajectory;
  r.strategies = {ParseCompareStrategy("STA"), ParseCompareStrategy("STE")};
  r.strategies_given = false;
  r.counts = {1};
  r.validation_reps = {10};
  const MethodComparison c = CompareMethods(r);
  ASSERT_TRUE(c.refusal.empty()) << c.refusal;
  ASSERT_EQ(c.rows.size(), 2u);
  EXPECT_EQ(c.rows[1].strategy, "all");
  r.strategies_given = true;  // named by the user: refused, saying which labels are missing
  EXPECT_EQ(CompareMethods(r).refusal.rfind("strategy STA needs trajectories the data set "
                                            "data/flower lacks: R1, R5, R9",
                                            0),
            0u);
}

}  // namespace
}  // namespace fitcal
