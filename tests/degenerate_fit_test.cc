// Degenerate data: a wheel that never turns, all runs identical, one run with gross
// slip. The fit must finish, the diagnostics (diagnosis/degenerate_data.h) must say what is wrong,
// and with a robust loss one slipping run must not drag the parameters.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "diagnosis/degenerate_data.h"
#include "fit/final_pose_errors.h"
#include "fit/run_split.h"
#include "tests/omni3_fit_support.h"
#include "tests/omni3_reference_replay.h"
#include "tests/flower_scenario.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace {

using testing::FitOmni3;
using testing::FitOmni3Nlopt;
using testing::Omni3Errors;

std::vector<AlignedRun> Simulate(std::uint64_t seed, int repetitions) {
  sim::FlowerSimulation options = sim::PalacinFlower();  // documented default noise
  options.options.seed = seed;
  options.repetitions = repetitions;
  std::vector<RunLog> logs = sim::SimulateFlowerLogs(options);
  return AlignRuns(logs);
}

// The simulator's robot as the seam describes it (FindDegenerateData serves every model).
Robot PalacinRobot() { return Omni3ModelOf(sim::PalacinApr02Robot())->robot(); }

bool Mentions(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& line : lines) {
    if (line.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST(DegenerateFit, CleanDataRaiseNoProblem) {
  const std::vector<AlignedRun> runs = Simulate(1, 1);
  EXPECT_TRUE(FindDegenerateData(runs, PalacinRobot()).empty());
}

TEST(DegenerateFit, WheelThatNeverTurnsIsNamedAndTheFitFinishes) {
  std::vector<AlignedRun> runs = Simulate(1, 1);
  for (AlignedRun& run : runs) {
    for (auto&& s : run.samples) s.value[2] = 0.0;  // encoder c disconnected
  }
  const std::vector<std::string> problems = FindDegenerateData(runs, PalacinRobot());
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("wheel c never turns"), std::string::npos) << problems[0];
  const ModelFitResult fit = FitOmni3(runs, sim::PalacinApr02Robot());
  EXPECT_FALSE(fit.termination.empty());
  // r_c has no influence on any residual: the fit cannot move it from the nominal.
  EXPECT_EQ(fit.parameters[omni3::kRadiusIndex + 2], sim::PalacinApr02Robot().nominal.radius_m[2]);
}

TEST(DegenerateFit, IdenticalRunsAreNamedAndTheFitFinishes) {
  const std::vector<AlignedRun> simulated = Simulate(1, 1);
  std::vector<AlignedRun> runs(6, simulated[3]);
  for (std::size_t i = 0; i < runs.size(); ++i) runs[i].id = "copy" + std::to_string(i);
  const std::vector<std::string> problems = FindDegenerateData(runs, PalacinRobot());
  EXPECT_TRUE(Mentions(problems, "all 6 runs have identical encoder logs")) << problems.size();
  const ModelFitResult fit = FitOmni3(runs, sim::PalacinApr02Robot());
  EXPECT_FALSE(fit.termination.empty());
  // 3 residuals for 9 parameters: no honest covariance exists, and the fit says so.
  EXPECT_FALSE(fit.has_covariance) << "a covariance was claimed for an underdetermined fit";
  EXPECT_FALSE(fit.covariance_message.empty());

  // Two copies among distinct runs: named, not "all".
  std::vector<AlignedRun> some = simulated;
  some.push_back(simulated[0]);
  some.back().id = "copy-of-" + simulated[0].id;
  const std::vector<std::string> copies = FindDegenerateData(some, PalacinRobot());
  ASSERT_EQ(copies.size(), 1u);
  EXPECT_NE(copies[0].find(simulated[0].id + " and copy-of-" + simulated[0].id), std::string::npos)
      << copies[0];
}

TEST(DegenerateFit, OutlierTestThresholdIsTheChiSquareQuantile) {
  // chi^2_1 quantiles: 0.5 -> 0.4549, 0.95 -> 3.841, 0.999 -> 10.83 (standard tables).
  EXPECT_NEAR(ChiSquare1Quantile(0.5), 0.4549, 1e-3);
  EXPECT_NEAR(ChiSquare1Quantile(0.95), 3.841, 1e-3);
  EXPECT_NEAR(ChiSquare1Quantile(0.999), 10.828, 1e-2);
  // Equal errors: nothing flagged; one 10x the rest: flagged with its ratio.
  std::vector<std::string> ids = {"a", "b", "c", "d", "e", "f", "g", "h"};
  std::vector<double> norms(8, 0.01);
  EXPECT_TRUE(FindOutlierRuns(ids, norms).empty());
  norms[5] = 0.1;
  const std::vector<OutlierRun> out = FindOutlierRuns(ids, norms);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, "f");
  EXPECT_NEAR(out[0].error_ratio, 10.0, 1e-9);
}

// One training run slips: its wheel a turns 10x the typical final-pose error further than the
// robot moved. Least squares is pulled; the Cauchy loss keeps the other parameters where the
// clean data put them.
TEST(DegenerateFit, GrossSlipIsFlaggedAndTheRobustLossKeepsTheParameters) {
  const std::vector<AlignedRun> all = Simulate(7, 1);
  const auto truth = sim::PalacinTable5Parameters().ToArray();
  const ModelFitResult clean = FitOmni3(all, sim::PalacinApr02Robot());
  ASSERT_TRUE(clean.usable && clean.has_covariance) << clean.covariance_message;
  const FinalPoseErrors clean_errors = Omni3Errors(clean.parameters, all);
  std::vector<double> sorted = clean_errors.per_run_cf;
  std::sort(sorted.begin(), sorted.end());
  const double typical = sorted[sorted.size() / 2];

  // Pick a translating run and scale wheel a so that its final pose moves by 10x typical.
  std::vector<AlignedRun> slipped = all;
  const std::size_t victim = 0;
  auto shift_for = [&](double factor) {
    AlignedRun run = all[victim];
    for (auto&& s : run.samples) s.value[0] *= factor;
    const Pose2d a = omni3::ReplayFinalPose(truth.data(), all[victim].samples, all[victim].start);
    const Pose2d b = omni3::ReplayFinalPose(truth.data(), run.samples, run.start);
    return std::hypot(std::hypot(b.x - a.x, b.y - a.y), WrapAngle(b.theta - a.theta));
  };
  const double slip = 0.01 * 10.0 * typical / shift_for(1.01);
  for (auto&& s : slipped[victim].samples) s.value[0] *= 1.0 + slip;
  ASSERT_NEAR(shift_for(1.0 + slip) / typical, 10.0, 1.0);

  const ModelFitResult least_squares = FitOmni3(slipped, sim::PalacinApr02Robot());
  ASSERT_TRUE(least_squares.usable);
  std::vector<std::string> ids;
  for (const AlignedRun& run : slipped) ids.push_back(run.id);
  const std::vector<OutlierRun> outliers =
      FindOutlierRuns(ids, Omni3Errors(least_squares.parameters, slipped).per_run_cf);
  ASSERT_EQ(outliers.size(), 1u);
  EXPECT_EQ(outliers[0].id, all[victim].id);

  CeresFitOptions robust_options;
  robust_options.loss = CeresRobustLoss::kCauchy;
  robust_options.loss_scale = 3.0 * typical;  // a few times the clean runs' error
  const ModelFitResult robust = FitOmni3(slipped, sim::PalacinApr02Robot(), robust_options);
  ASSERT_TRUE(robust.usable);
  // Tolerance: the clean fit's own uncertainty (4.5 sigma, as tests/omni3_fit_test.cc) around
  // the truth; the slipping run must not push any parameter out of it.
  double worst_ls = 0.0, worst_robust = 0.0;
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    EXPECT_NEAR(robust.parameters[k], truth[k], 4.5 * clean.sigma[k]) << "parameter " << k;
    worst_robust = std::max(worst_robust,
                            std::abs(robust.parameters[k] - clean.parameters[k]) / clean.sigma[k]);
    worst_ls = std::max(
        worst_ls, std::abs(least_squares.parameters[k] - clean.parameters[k]) / clean.sigma[k]);
  }
  // And the test can fail: least squares moved further than the robust fit.
  EXPECT_GT(worst_ls, 2.0 * worst_robust) << worst_ls << " vs " << worst_robust;
}

}  // namespace
}  // namespace fitcal
