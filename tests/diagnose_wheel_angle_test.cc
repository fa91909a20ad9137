// An error periodic in a wheel's revolution: an eccentric wheel
// whose runs each start at another absolute wheel angle scatters the repetitions of a trajectory
// differently every time, so the lack of fit takes it as noise. When the logs carry the wheels'
// absolute angles (cumulative counts), diagnose tests the residual against them
// (diagnosis/covariate_structure.h) and names the covariate; with round wheels it stays silent.

#include <gtest/gtest.h>

#include <cstdio>

#include "diagnosis/diagnose.h"
#include "fit/run_split.h"
#include "models/omni3/omni3_robot_model.h"
#include "tests/flower_scenario.h"
#include "tests/test_paths.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace diagnose_wheel_angle_test {  // named, not anonymous: tests compile in batches (tests/CMakeLists.txt)

Omni3Robot NominalRobot() { return ReadOmni3Robot(FITCAL_SOURCE_DIR + "/data/robots/apr02.yaml"); }

// Every third flower trajectory (12 of 36), four repetitions (1-2 train, 3-4 validate), each run
// at random absolute wheel angles; wheel a's rolling radius r_a (1 + e cos A_a).
DiagnoseResult DiagnoseEccentric(double eccentricity, std::uint64_t seed) {
  sim::FlowerSimulation o = sim::PalacinFlower();
  const auto flower = sim::FlowerTrajectories();
  o.trajectories.clear();
  for (std::size_t i = 0; i < flower.size(); i += 3) o.trajectories.push_back(flower[i]);
  o.repetitions = 4;
  o.options.seed = seed;
  o.options.stepped->random_wheel_start_angle = true;
  o.options.stepped->wheel_eccentricity = {eccentricity, 0.0, 0.0};
  const Omni3Robot robot = NominalRobot();
  o.options.stepped->commanded_parameters = sim::ParameterVector(robot.nominal);
  std::vector<RunLog> logs = sim::SimulateFlowerLogs(o);
  const SplitOf<TrackRun> split = SplitByRepetition(PrepareTrackRuns(logs), {1, 2});
  DiagnoseOptions options;
  options.max_effects = 1;
  return Diagnose(split.training, split.validation, *Omni3ModelOf(robot), options);
}

const CovariateTest& WheelAngleTest(const DiagnoseResult& r) {
  for (const CovariateTest& t : r.covariates.tests) {
    if (t.name == "absolute wheel angle") return t;
  }
  ADD_FAILURE() << "no wheel-angle covariate";
  return r.covariates.tests.front();
}

// e = 2 %: wheel a's travel per revolution is unchanged, but a run's final pose moves by
// r e (sin A_end - sin A_start) along the wheel (~3 mm, and ~0.9 deg of heading through its
// lever arm), at a phase that changes from run to run: the repetitions' scatter holds it and the
// lack of fit does not see it. Power measured over seeds 1-12: named in 11 of 12 at e = 2 %, 7 of
// 12 at 1.5 %; clean, 0 of 12 report any structure.
TEST(WheelAngle, EccentricWheelIsNamedAsTheAbsoluteWheelAngle) {
  const DiagnoseResult r = DiagnoseEccentric(0.02, 1);
  const std::string report = FormatDiagnoseReport(r, *Omni3ModelOf(NominalRobot()));
  SCOPED_TRACE(report);
  const CovariateTest& t = WheelAngleTest(r);
  std::printf(
      "eccentric wheel: F = %.2f on (%.0f, %.0f) df, p = %.2g; lack of fit F = %.2f, "
      "p = %.2g\n",
      t.f, t.df1, t.df2, t.p_value, r.after.lack_of_fit.f, r.after.lack_of_fit.p_value);
  ASSERT_TRUE(t.tested) << t.why_not;
  EXPECT_TRUE(t.significant);
  EXPECT_TRUE(r.unexplained_structure);
  EXPECT_FALSE(r.effects_named);
  EXPECT_EQ(report.find("consistent with the noise floor"), std::string::npos);
  EXPECT_NE(report.find("unexplained: the residual depends on the absolute wheel angle"),
            std::string::npos);
}

// The same runs with round wheels: the covariate is tested (the angles are carried) and not
// significant; nothing is reported. (The clean 20-seed rate with every covariate, this one
// included, is diagnose_test's CleanDataAcceptsNoEffectOverTwentySeeds.)
TEST(WheelAngle, RoundWheelsStaySilent) {
  const DiagnoseResult r = DiagnoseEccentric(0.0, 1);
  const CovariateTest& t = WheelAngleTest(r);
  ASSERT_TRUE(t.tested) << t.why_not;
  EXPECT_FALSE(t.significant) << "p = " << t.p_value;
  EXPECT_FALSE(r.unexplained_structure) << FormatDiagnoseReport(r, *Omni3ModelOf(NominalRobot()));
}

}  // namespace
}  // namespace fitcal
