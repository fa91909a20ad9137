// validation/parameter_covariance.h against the textbook straight-line fit: y = a + b x at
// x = 0, 1, 2, 3 has J^T J = [[4, 6], [6, 14]], (J^T J)^-1 = [[14, -6], [-6, 4]] / 20, so with
// |r|^2 = 2 on dof = 2 (s = 1): sigma_a = sqrt(0.7), sigma_b = sqrt(0.2),
// corr(a, b) = -6 / sqrt(14 * 4).

#include "validation/parameter_covariance.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fitcal {
namespace {

constexpr double kTol = 1e-12;  // a 2 x 2 solve in double: rounding only

TEST(ParameterCovariance, StraightLineFitMatchesTheClosedForm) {
  Eigen::MatrixXd j(4, 2);
  j << 1, 0, 1, 1, 1, 2, 1, 3;
  const ParameterCovariance c = CovarianceFromJacobian(j, 2.0, 2);
  ASSERT_EQ(c.sigma.size(), 2u);
  EXPECT_NEAR(c.residual_sigma, 1.0, kTol);
  EXPECT_NEAR(c.sigma[0], std::sqrt(0.7), kTol);
  EXPECT_NEAR(c.sigma[1], std::sqrt(0.2), kTol);
  EXPECT_NEAR(c.correlation[0][1], -6.0 / std::sqrt(56.0), kTol);
  EXPECT_NEAR(c.correlation[1][0], c.correlation[0][1], kTol);
  EXPECT_NEAR(c.correlation[0][0], 1.0, kTol);
}

TEST(ParameterCovariance, ScalesWithTheResidualVariance) {
  Eigen::MatrixXd j(4, 2);
  j << 1, 0, 1, 1, 1, 2, 1, 3;
  const ParameterCovariance c = CovarianceFromJacobian(j, 8.0, 2);  // s = 2
  EXPECT_NEAR(c.residual_sigma, 2.0, kTol);
  EXPECT_NEAR(c.sigma[0], 2.0 * std::sqrt(0.7), kTol);
  EXPECT_NEAR(c.correlation[0][1], -6.0 / std::sqrt(56.0), kTol);  // unchanged by the scale
}

TEST(ParameterCovariance, ZeroSigmaHasNoCorrelation) {
  Eigen::MatrixXd j(3, 2);
  j << 1, 0, 0, 1, 1, 1;
  const ParameterCovariance c = CovarianceFromJacobian(j, 0.0, 1);  // a perfect fit
  EXPECT_EQ(c.sigma[0], 0.0);
  EXPECT_EQ(c.correlation[0][0], 1.0);
  EXPECT_EQ(c.correlation[0][1], 0.0);
}

}  // namespace
}  // namespace fitcal
