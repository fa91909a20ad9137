// What to drive (fit/motion_advice.h): closed circles of a differential drive leave the common
// scale of its wheels and track undetermined (every circle ends where it started whatever the
// scale); the advice names a straight run, never a turn on the spot (which the common scale does
// not move either) nor a sideways run (which a differential drive cannot drive), and the number of
// runs it names is the one the analysis itself then finds enough.

#include "fit/motion_advice.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>

#include "fit/model_fit.h"
#include "models/model_registry.h"
#include "tests/model_support.h"

namespace fitcal {
namespace motion_advice_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

// A noise-free run of `motion` at the nominal, its end moved by a deterministic error of 2 mm and
// 0.2 deg (the order of a motion-capture pose): the residuals' noise the analysis reads.
AlignedRun NoisyRun(const RobotModelInterface& model, const StandardMotion& motion, int index) {
  AlignedRun run;
  EXPECT_TRUE(RunOfMotion(model, model.robot().nominal, motion, &run));
  const double sign = index % 2 == 0 ? 1.0 : -1.0;
  run.id += "-" + std::to_string(index);
  run.final_ground_truth.x += sign * 0.002;
  run.final_ground_truth.y -= sign * 0.002 * ((index % 3) - 1);
  run.final_ground_truth.theta += sign * 0.0035;
  return run;
}

StandardMotion Circle(double omega_sign) {
  return {omega_sign > 0 ? "circle left" : "circle right", {0.3, 0.0, 0.3 * omega_sign},
          2.0 * M_PI / 0.3};
}

// The undetermined direction in which all three parameters move together (the common scale).
const UndeterminedDirection* CommonScale(const DirectionAnalysis& analysis) {
  for (const UndeterminedDirection& d : analysis.undetermined) {
    const Eigen::VectorXd& v = d.prior_units;
    if ((v.array() > 0.2).all() || (v.array() < -0.2).all()) return &d;
  }
  return nullptr;
}

TEST(MotionAdvice, ClosedCirclesOfADiffDriveAreAdvisedAStraightRun) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  const std::vector<double>& p = model->robot().nominal;
  std::vector<AlignedRun> circles;
  for (int i = 0; i < 6; ++i) circles.push_back(NoisyRun(*model, Circle(i % 2 ? -1.0 : 1.0), i));
  const DirectionAnalysis analysis =
      AnalyseDeterminedDirections(circles, *model, p, testing::Unweighted(circles), nullptr, 1);
  ASSERT_TRUE(analysis.ok);
  const UndeterminedDirection* scale = CommonScale(analysis);
  ASSERT_NE(scale, nullptr) << "closed circles must leave the common scale undetermined";

  const std::vector<MotionThatDetermines> advice =
      MotionsThatDetermine(*scale, *model, p, ResidualWeights{});
  ASSERT_FALSE(advice.empty());
  const auto named = [&](const std::string& words) {
    return std::any_of(advice.begin(), advice.end(),
                       [&](const MotionThatDetermines& m) { return m.words == words; });
  };
  EXPECT_TRUE(named("a straight run of 2 m"));
  EXPECT_FALSE(named("a half turn on the spot"));  // the common scale keeps every turn rate
  EXPECT_FALSE(named("a sideways run of 2 m"));    // not drivable
  EXPECT_NE(MotionAdviceLine(advice).find("a straight run of 2 m"), std::string::npos);

  // The advice's count, checked by the analysis itself: that many straight runs added, the
  // common scale is determined.
  int straight_runs = 0;
  for (const MotionThatDetermines& m : advice)
    if (m.words == "a straight run of 2 m") straight_runs = m.runs;
  std::vector<AlignedRun> with_straight = circles;
  for (int i = 0; i < straight_runs; ++i)
    with_straight.push_back(NoisyRun(*model, StandardMotions()[0], 100 + i));
  const DirectionAnalysis after = AnalyseDeterminedDirections(
      with_straight, *model, p, testing::Unweighted(with_straight), nullptr, 1);
  ASSERT_TRUE(after.ok);
  EXPECT_EQ(CommonScale(after), nullptr);
}

// The fit's own analysis weighs each run as the fit does (ModelFitOptions::weights_per_run, as
// per-session noise levels set them): straight runs weighed 1000 times noisier than the circles
// bring 1e-6 of their information, so the common scale the circles leave open is held at the
// nominal; weighed alike they determine it. The analysis read the data set's weights for every
// run before, and then held nothing here.
TEST(MotionAdvice, RunsTheFitHardlyWeighsDetermineNothing) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  std::vector<AlignedRun> runs;
  for (int i = 0; i < 6; ++i) runs.push_back(NoisyRun(*model, Circle(i % 2 ? -1.0 : 1.0), i));
  for (int i = 0; i < 4; ++i) runs.push_back(NoisyRun(*model, StandardMotions()[0], 100 + i));
  const auto held_with_straight_sigma = [&](double sigma) {
    ModelFitOptions options;
    options.weights_per_run.resize(runs.size());
    for (std::size_t i = 6; i < runs.size(); ++i)
      options.weights_per_run[i].final_pose = ResidualWeights{sigma, sigma};
    return FitModel(runs, *model, options).held_directions;
  };
  EXPECT_TRUE(held_with_straight_sigma(1.0).empty());
  const std::vector<UndeterminedDirection> held = held_with_straight_sigma(1000.0);
  DirectionAnalysis as_held;
  as_held.undetermined = held;
  EXPECT_NE(CommonScale(as_held), nullptr) << held.size() << " directions held";
}

TEST(MotionAdvice, MotionsAModelCannotDriveAreSkipped) {
  const RobotModelPtr model = testing::ExampleModel("diff_drive");
  AlignedRun run;
  EXPECT_FALSE(RunOfMotion(*model, model->robot().nominal, StandardMotions()[1], &run));
  ASSERT_TRUE(RunOfMotion(*model, model->robot().nominal, StandardMotions()[0], &run));
  // The noise-free run replays to the twist's exact end (2 m straight ahead).
  const Pose2d end = model->ReplayFinalPose(model->robot().nominal.data(), run.samples, run.start);
  EXPECT_NEAR(end.x, 2.0, 1e-9);
  EXPECT_NEAR(run.final_ground_truth.x, 2.0, 1e-12);
}

}  // namespace
}  // namespace fitcal
