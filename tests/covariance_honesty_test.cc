// Are the reported uncertainties honest? On simulated data with known true parameters (Palacin
// Table 5) and the simulator's documented noise, the fitted parameters must lie within 3 reported
// sigmas of the truth in at least 95 % of (parameter, seed) pairs over 20 seeds. For Gaussian
// errors and honest sigmas 99.7 % would; 95 % leaves room for the non-Gaussian slip and for the
// scatter of a variance estimated from few residuals. Sigmas that are too small fail the count;
// sigmas that are simply huge (e.g. the unscaled (J^T J)^-1 of this unit-weight problem, whose
// residual sigma is ~0.005, i.e. ~200x too large) would pass it, so the mean reported sigma of
// every parameter must also lie within a factor 2 of the observed rms error over the 20 seeds
// (the rms of 20 errors is itself uncertain by ~16 %, sqrt(1/40)).

#include <gtest/gtest.h>

#include <cmath>

#include "tests/omni3_fit_support.h"
#include "tests/flower_scenario.h"
#include "tests/omni3_robot.h"

namespace fitcal {
namespace {

using testing::FitOmni3;
using testing::FitOmni3Nlopt;
using testing::Omni3Errors;

struct HonestyCount {
  int inside = 0;
  int total = 0;
  std::array<double, omni3::kNumParameters> rms_error{};
  std::array<double, omni3::kNumParameters> mean_sigma{};
};

HonestyCount CountInside(int seeds) {
  HonestyCount count;
  const Omni3Robot robot = sim::PalacinApr02Robot();
  const auto truth = sim::PalacinTable5Parameters().ToArray();
  for (int seed = 1; seed <= seeds; ++seed) {
    sim::FlowerSimulation options = sim::PalacinFlower();
    options.options.seed = static_cast<std::uint64_t>(seed);
    options.repetitions = 1;  // one repetition of the whole flower (36 runs): STE-1
    std::vector<AlignedRun> runs;
    for (const auto& run : sim::SimulateFlower(options)) runs.push_back(AlignRun(run.log));
    CeresFitOptions fit_options;
    fit_options.num_threads = 1;
    const ModelFitResult fit = FitOmni3(runs, robot, fit_options);
    EXPECT_TRUE(fit.usable) << "seed " << seed;
    EXPECT_TRUE(fit.has_covariance) << "seed " << seed;
    for (int k = 0; k < omni3::kNumParameters; ++k) {
      const double error = std::abs(fit.parameters[k] - truth[k]);
      count.inside += error <= 3.0 * fit.sigma[k] ? 1 : 0;
      ++count.total;
      count.rms_error[k] += error * error / seeds;
      count.mean_sigma[k] += fit.sigma[k] / seeds;
    }
  }
  for (double& e : count.rms_error) e = std::sqrt(e);
  return count;
}

TEST(CovarianceHonestyTest, TruthWithinThreeSigmaInAtLeast95PercentOfPairs) {
  const HonestyCount c = CountInside(20);
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    const double ratio = c.mean_sigma[k] / c.rms_error[k];
    std::printf("parameter %d: rms error %.3g, mean reported sigma %.3g (ratio %.2f)\n", k,
                c.rms_error[k], c.mean_sigma[k], ratio);
    EXPECT_GT(ratio, 0.5) << "parameter " << k;
    EXPECT_LT(ratio, 2.0) << "parameter " << k;
  }
  std::printf("inside 3 sigma: %d of %d\n", c.inside, c.total);
  EXPECT_GE(c.inside, static_cast<int>(std::ceil(0.95 * c.total)));
}

}  // namespace
}  // namespace fitcal
