#pragma once
// The correlation matrix of a covariance, corr(r, c) = cov(r, c) / (sigma_r sigma_c). A parameter
// without variance (held at nominal, or not determined) correlates with nothing but itself.

#include <Eigen/Core>
#include <cmath>

namespace fitcal {

inline Eigen::MatrixXd CorrelationOf(const Eigen::MatrixXd& covariance) {
  const Eigen::Index n = covariance.rows();
  Eigen::MatrixXd correlation = Eigen::MatrixXd::Identity(n, n);
  for (Eigen::Index r = 0; r < n; ++r) {
    for (Eigen::Index c = 0; c < n; ++c) {
      const double d = covariance(r, r) * covariance(c, c);
      if (d > 0.0) correlation(r, c) = covariance(r, c) / std::sqrt(d);
    }
  }
  return correlation;
}

}  // namespace fitcal
