// The NLopt methods for every model on the seam (fit/model_nlopt_fit.h): on each model's simulated
// calibration runs they reach the minimum of Palacin Eq. 14 that the Ceres fit brackets, hold the
// gauge, and give the same bits for the same seed on any thread count; through the command line,
// `fit --method <NLopt method>` and `compare` work for a model other than omni3, compare with the
// model's closed form (UMBmark) as a row.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "fit/final_pose_errors.h"
#include "fit/model_fit.h"
#include "fit/model_nlopt_fit.h"
#include "models/model_registry.h"
#include "odometry/aligned_run.h"
#include "tests/model_support.h"
#include "tests/test_files.h"
#include "sim/model_scenarios.h"

namespace fitcal {
namespace {

using fitcal::testing::ExampleModel;
using fitcal::testing::ReadFileBytes;
using fitcal::testing::RunFitcal;
using fitcal::testing::TempDir;

// One repetition of the model's calibration trajectories, driven by its default true robot, with
// the default noise (model_scenarios.h).
std::vector<AlignedRun> SimulatedRuns(const RobotModelInterface& model) {
  sim::ScenarioNoise noise;
  noise.repetitions = 1;
  noise.seed = 7;
  const std::vector<double> truth = sim::DefaultTrueParameters(model.robot());
  const sim::ModelScenario scenario = sim::MakeModelScenario(model, truth, noise);
  std::vector<RunLog> logs;
  for (auto& run : sim::SimulateRuns(model, truth, scenario.trajectories, scenario.options)) {
    logs.push_back(std::move(run.log));
  }
  return AlignRuns(logs);
}

struct MethodCase {
  const char* model;
  NloptMethod method;
};

class EveryModelNlopt : public ::testing::TestWithParam<MethodCase> {};

// The reference is the better of the two Ceres fits (sum of squares, and Eq. 14 itself as a loss):
// NLopt minimises Eq. 14 and must reach it within 2 % (a global search stops on its budget or its
// tolerance, not exactly at the minimum); the nominal is far worse (the test can fail).
TEST_P(EveryModelNlopt, ReachesTheCeresOptimumAndHoldsTheGauge) {
  const MethodCase c = GetParam();
  const RobotModelPtr model = ExampleModel(c.model);
  const Robot& robot = model->robot();
  const std::vector<AlignedRun> runs = SimulatedRuns(*model);
  ModelFitOptions ceres;
  ceres.ceres.compute_covariance = false;
  double best_ceres_cf =
      EvaluateFinalPoseErrors(*model, FitModel(runs, *model, ceres).parameters, runs, 1).cf;
  ceres.ceres.objective = FinalPoseObjective::kSumOfNorms;
  best_ceres_cf = std::min(
      best_ceres_cf,
      EvaluateFinalPoseErrors(*model, FitModel(runs, *model, ceres).parameters, runs, 1).cf);

  NloptFitOptions options;
  options.method = c.method;
  options.max_evaluations = 6000;
  options.local_polish = Info(c.method).global;
  options.local_polish_evaluations = 1000;
  const NloptSearchResult fit = FitModelNlopt(runs, *model, options);
  ASSERT_TRUE(fit.usable) << fit.message;
  const double cf = EvaluateFinalPoseErrors(*model, fit.parameters, runs, 1).cf;
  std::printf("%s %s: CF %.6f (Ceres %.6f, nominal %.6f), %d evaluations\n", c.model,
              Info(c.method).name, cf, best_ceres_cf, fit.initial_cf, fit.evaluations);
  EXPECT_NEAR(cf, fit.final_cf, 1e-12);  // the search's CF is Eq. 14 with weights of 1
  EXPECT_LT(cf, 1.02 * best_ceres_cf);
  EXPECT_GT(fit.initial_cf, 3.0 * best_ceres_cf);
  for (const HeldParameter& h : robot.held) {
    EXPECT_EQ(fit.parameters[h.index], robot.nominal[h.index]) << robot.parameters[h.index].name;
  }
}

INSTANTIATE_TEST_SUITE_P(Models, EveryModelNlopt,
                         ::testing::Values(MethodCase{"diff_drive", NloptMethod::kCrs2Lm},
                                           MethodCase{"diff_drive", NloptMethod::kSlsqp},
                                           MethodCase{"diff_drive", NloptMethod::kBobyqa},
                                           MethodCase{"tricycle", NloptMethod::kCrs2Lm},
                                           MethodCase{"tricycle", NloptMethod::kMma},
                                           MethodCase{"omni", NloptMethod::kSlsqp},
                                           MethodCase{"omni", NloptMethod::kSbplx}),
                         [](const auto& test) {
                           std::string name =
                               std::string(test.param.model) + "_" + Info(test.param.method).name;
                           for (char& ch : name)
                             ch = std::isalnum(static_cast<unsigned char>(ch)) ? ch : '_';
                           return name;
                         });

TEST(ModelNlopt, SameSeedSameBitsOnAnyThreadCountOtherSeedOtherPath) {
  const RobotModelPtr model = ExampleModel("tricycle");
  const std::vector<AlignedRun> runs = SimulatedRuns(*model);
  NloptFitOptions options;
  options.method = NloptMethod::kCrs2Lm;
  options.max_evaluations = 800;
  options.seed = 3;
  options.num_threads = 1;
  const NloptSearchResult a = FitModelNlopt(runs, *model, options);
  options.num_threads = 2;
  const NloptSearchResult b = FitModelNlopt(runs, *model, options);
  options.seed = 4;
  const NloptSearchResult c = FitModelNlopt(runs, *model, options);
  ASSERT_EQ(a.parameters.size(), b.parameters.size());
  EXPECT_EQ(0, std::memcmp(a.parameters.data(), b.parameters.data(),
                           a.parameters.size() * sizeof(double)));
  EXPECT_EQ(a.evaluations, b.evaluations);
  EXPECT_NE(0, std::memcmp(a.parameters.data(), c.parameters.data(),
                           a.parameters.size() * sizeof(double)));
}

// ---- the command line ----

TEST(ModelNloptCli, FitAndCompareWorkForADifferentialDrive) {
  TempDir dir;
  const std::string data = dir.Path("data");
  const auto simulated =
      RunFitcal(dir, "simulate --model diff_drive --repetitions 3 --seed 2 --out " + data);
  ASSERT_EQ(simulated.exit_code, 0) << simulated.err;
  const std::string cal = dir.Path("cal.yaml");
  const auto fit =
      RunFitcal(dir, "fit --logs " + data + " --method crs2lm --polish --max-evaluations 3000 " +
                         "--train-reps 1-2 --out " + cal);
  ASSERT_EQ(fit.exit_code, 0) << fit.err << fit.out;
  EXPECT_NE(fit.out.find("NLopt CRS2-LM"), std::string::npos) << fit.out;
  EXPECT_NE(ReadFileBytes(cal).find("method: crs2lm"), std::string::npos);

  const std::string prefix = dir.Path("cmp");
  const auto compared =
      RunFitcal(dir, "compare --logs " + data +
                         " --methods ceres slsqp --repetitions 1 2 --quiet --out " + prefix);
  ASSERT_EQ(compared.exit_code, 0) << compared.err << compared.out;
  const std::string csv = ReadFileBytes(prefix + ".csv");
  // The default strategy of a model without flower labels is "all"; UMBmark is a row per k.
  EXPECT_NE(csv.find("r_right_m,r_left_m,wheel_separation_m"), std::string::npos) << csv;
  EXPECT_NE(csv.find("all,umbmark,1,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("all,umbmark,2,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("all,slsqp,2,"), std::string::npos) << csv;
  // A flower strategy on squares and circles is refused in one line.
  const auto refused =
      RunFitcal(dir, "compare --logs " + data + " --strategies STA --quiet --no-output");
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_EQ(testing::Lines(refused.err), 1) << refused.err;
}

// A global search that ends where its objective still falls is written with a warning (exit 6),
// as a solver stopped at its limit: DIRECT-L on OptiOdom's tricycle squares stops on its function
// tolerance at a point of its box's grid (stop 72's D-F11: held-out CF 0.54 where the polished
// search reaches 0.14, exit 0, its parameters "NOT DETERMINED"). The check is the polish itself:
// from that point a local method lowers the training CF by more than the tenth the warning needs.
TEST(ModelNloptCli, AGlobalSearchEndingShortOfAMinimumIsFlagged) {
  const std::string squares = FITCAL_SHARED_DIR + "/data/optiodom/tricyc/square";
  if (!std::filesystem::is_directory(squares)) GTEST_SKIP() << "no " << squares;
  TempDir dir;
  const std::string data = dir.Path("sq"), raw = dir.Path("raw.yaml"), polished = dir.Path("p.yaml");
  ASSERT_EQ(RunFitcal(dir, "import optiodom " + squares + "/* --out " + data).exit_code, 0);
  const auto short_of = RunFitcal(dir, "fit --logs " + data + " --method direct-l --out " + raw);
  EXPECT_EQ(short_of.exit_code, 6) << short_of.out << short_of.err;
  EXPECT_EQ(testing::Lines(short_of.err), 1) << short_of.err;
  EXPECT_NE(short_of.err.find("is not a minimum"), std::string::npos) << short_of.err;
  EXPECT_NE(short_of.err.find("--polish"), std::string::npos) << short_of.err;
  const auto finished =
      RunFitcal(dir, "fit --logs " + data + " --method direct-l --polish --out " + polished);
  ASSERT_EQ(finished.exit_code, 0) << finished.out << finished.err;
  const auto training_cf = [](const std::string& cal) {
    return YAML::LoadFile(cal)["calibration"]["cf_training"]["after"].as<double>();
  };
  EXPECT_LT(training_cf(polished), 0.9 * training_cf(raw));
}

}  // namespace
}  // namespace fitcal
