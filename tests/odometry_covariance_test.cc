// The pieces of the odometry covariance (validation/odometry_covariance.h) on inputs whose answer
// is known; its coverage of the true motion is checked on the independent simulator
// (tests/independent_odometry_covariance_test.cc).

#include "validation/odometry_covariance.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fitcal {
namespace {

// Exact mean squares of c + beta T + alpha T^2 give the coefficients back (to rounding).
TEST(OdometryCovariance, StructureFunctionRecoversItsCoefficients) {
  const double c = 2e-6, beta = 3e-7, alpha = 4e-6;
  std::vector<double> t, v, w;
  for (double lag : {0.02, 0.04, 0.08, 0.16, 0.32, 0.64, 1.28}) {
    t.push_back(lag);
    v.push_back(c + beta * lag + alpha * lag * lag);
    w.push_back(1000.0 / (v.back() * v.back()));
  }
  const std::array<double, 3> f = FitStructureFunction(t, v, w);
  EXPECT_NEAR(f[0], c, 1e-12);
  EXPECT_NEAR(f[1], beta, 1e-12);
  EXPECT_NEAR(f[2], alpha, 1e-12);
}

// A coefficient the data would make negative is held at 0 (a variance never is).
TEST(OdometryCovariance, StructureFunctionKeepsEveryTermNonNegative) {
  const std::vector<double> t = {0.02, 0.04, 0.08, 0.16, 0.32};
  std::vector<double> v, w;
  for (double lag : t) {
    v.push_back(1e-6 + 1e-6 * lag - 1e-7 * lag * lag);  // alpha < 0
    w.push_back(1.0 / (v.back() * v.back()));
  }
  const std::array<double, 3> f = FitStructureFunction(t, v, w);
  for (double x : f) EXPECT_GE(x, 0.0);
  EXPECT_GT(f[0], 0.0);
}

}  // namespace
}  // namespace fitcal
