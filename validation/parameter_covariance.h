#pragma once
// The covariance of parameters fitted by least squares, from the Jacobian J of the residuals at
// the solution (rows: residuals, columns: parameters) and their sum of squares |r|^2:
//   C = s^2 (J^T J)^-1,   s^2 = |r|^2 / dof,
// dof = residuals - parameters (e.g. 3 N - 9 for omni3's final-pose residuals of N runs, metres
// and radians weighed 1:1 as Palacin Eq. 14), as the fit computes it (fit/omni3_ceres_fit.h).
// The report shows it beside the parameters; validation/odometry_covariance.h is the other
// covariance, that of the odometry itself.

#include <Eigen/Dense>
#include <vector>

namespace fitcal {

struct ParameterCovariance {
  std::vector<double> sigma;                     // sqrt(C_kk), the parameters' units
  std::vector<std::vector<double>> correlation;  // C_ab / (sigma_a sigma_b); 1 on the diagonal
                                                 // and 0 elsewhere where a sigma is 0
  double residual_sigma = 0.0;                   // s
};

// dof must be positive and J^T J invertible (the caller checks the rank).
ParameterCovariance CovarianceFromJacobian(const Eigen::MatrixXd& jacobian,
                                           double sum_squared_residuals, int dof);

}  // namespace fitcal
