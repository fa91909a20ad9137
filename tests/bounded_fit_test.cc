// Bounded fits that converge (fit/model_fit.h, active set), on a case where the plain solve stalls:
// the real OptiOdom three-wheel robot, all 67 runs, in Palacin Eq. 16's box (R +- 0.025 m). Its
// tracked point sits ~3 cm off the kinematic centre, so the constrained minimum has a distance
// on its bound; Ceres' plain bounded solve then keeps shrinking projected steps and stops at
// the 100-iteration limit (NO_CONVERGENCE), while the active set converges on the bound. The
// test needs ../shared/data/optiodom (skipped without it).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "fit/model_fit.h"
#include "fit/parameter_tying.h"
#include "io/dataset.h"
#include "models/model_registry.h"
#include "models/omni3/omni3_robot_model.h"
#include "odometry/aligned_run.h"
#include "interchange/optiodom/optiodom_import.h"
#include "tests/dataset_edit.h"
#include "tests/test_paths.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace {

namespace fs = std::filesystem;

TEST(BoundedFit, RealOmni3InEq16sBoxConvergesOnTheBoundOnlyWithTheActiveSet) {
  const fs::path root = fs::path(FITCAL_SHARED_DIR) / "data" / "optiodom" / "omni3";
  if (!fs::is_directory(root)) GTEST_SKIP() << "no " << root;
  std::vector<AlignedRun> runs;
  Omni3Robot robot;
  for (const char* kind : {"circular", "square"}) {
    std::vector<fs::path> sessions;
    for (const auto& entry : fs::directory_iterator(root / kind)) sessions.push_back(entry.path());
    std::sort(sessions.begin(), sessions.end());
    for (const fs::path& dir : sessions) {
      const optiodom::OptiOdomImport session = optiodom::ReadOptiOdomSessions({dir.string()});
      robot = Omni3RobotOf(dynamic_cast<const Omni3Model&>(*session.model));
      for (const RunLog& run : session.runs) runs.push_back(AlignRun(run));
    }
  }
  ASSERT_EQ(runs.size(), 67u);
  robot.bounds.distance_m = {0.17, 0.22};  // Eq. 16: nominal 0.195 m +- 0.025 m
  const auto model = Omni3ModelOf(robot);

  ModelFitOptions options;
  options.ceres.num_threads = 2;
  options.ceres.compute_covariance = false;
  options.hold_undetermined = false;  // the bounds alone
  const ModelFitResult fit = FitModel(runs, *model, options);
  EXPECT_EQ(fit.termination, "CONVERGENCE") << fit.message;
  EXPECT_TRUE(fit.usable);
  EXPECT_TRUE(std::any_of(fit.at_bound.begin(), fit.at_bound.end(), [](bool b) { return b; }));

  options.active_set_bounds = false;  // Ceres' projected steps only
  const ModelFitResult plain = FitModel(runs, *model, options);
  EXPECT_EQ(plain.termination, "NO_CONVERGENCE") << plain.message;
  EXPECT_FALSE(plain.usable);
  // The active set, taking over at the first bound contact, ends lower than Ceres' crawl along the
  // bound, in fewer iterations than the crawl's limit.
  EXPECT_LT(fit.final_cost, plain.final_cost);
  EXPECT_LT(fit.iterations, plain.iterations);
}

// The active set releases a parameter from its bound when the fit's gradient points into the
// box; it reads that gradient by parameter index. A held parameter (a model's gauge, --hold) must
// not change it: until stop 66 the gradient came from a problem with the held parameters fixed,
// which Ceres gives in its tangent space - one entry short per held parameter, so g[k] was the
// next parameter's entry or lay past the end (valgrind, on a simulated ASOC whose fits differed
// from run to run). Held here through a tying that only holds (q = p): the same cost, so the same
// gradient, entry for entry, to the last bits the summation order leaves.
TEST(BoundedFit, AHeldParameterLeavesTheGradientTheActiveSetReads) {
  testing::TempDir dir;
  const std::string data = testing::SimulateDiffDrive(dir, "data");
  const io::DatasetIndex index = io::ReadDatasetIndex(data);
  const RobotModelPtr model = ReadRobotModelFile(index.robot_path);
  const std::vector<AlignedRun> runs = AlignRuns(io::LoadDataset(index, model->robot()).runs);
  const TiedModel held(*model, {{}, {"r_left"}});
  ASSERT_EQ(held.robot().held.size(), 1u);
  std::vector<double> p = model->robot().nominal;
  for (double& v : p) v *= 1.03;  // off the minimum: every entry of the gradient non-zero
  const std::vector<double> free_gradient = FitCostGradient(runs, *model, p);
  const std::vector<double> held_gradient = FitCostGradient(runs, held, p);
  ASSERT_EQ(held_gradient.size(), free_gradient.size());
  for (std::size_t k = 0; k < free_gradient.size(); ++k) {
    EXPECT_NE(free_gradient[k], 0.0) << k;
    EXPECT_NEAR(held_gradient[k], free_gradient[k], 1e-9 * std::abs(free_gradient[k])) << k;
  }
}

}  // namespace
}  // namespace fitcal
