#include "validation/parameter_covariance.h"

#include <algorithm>
#include <cmath>

namespace fitcal {

ParameterCovariance CovarianceFromJacobian(const Eigen::MatrixXd& jacobian,
                                           double sum_squared_residuals, int dof) {
  const Eigen::MatrixXd jtj = jacobian.transpose() * jacobian;
  const Eigen::MatrixXd cov = (sum_squared_residuals / dof) *
                              jtj.ldlt().solve(Eigen::MatrixXd::Identity(jtj.rows(), jtj.cols()));
  const int n = static_cast<int>(cov.rows());
  ParameterCovariance out;
  out.residual_sigma = std::sqrt(sum_squared_residuals / dof);
  out.sigma.assign(n, 0.0);
  out.correlation.assign(n, std::vector<double>(n));
  for (int k = 0; k < n; ++k) out.sigma[k] = std::sqrt(std::max(0.0, cov(k, k)));
  for (int a = 0; a < n; ++a) {
    for (int b = 0; b < n; ++b) {
      const double den = out.sigma[a] * out.sigma[b];
      out.correlation[a][b] = den > 0.0 ? cov(a, b) / den : (a == b ? 1.0 : 0.0);
    }
  }
  return out;
}

}  // namespace fitcal
