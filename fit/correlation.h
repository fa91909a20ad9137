#pragma once
// The sigmas and the correlation matrix of a covariance, corr(r, c) = cov(r, c) / (sigma_r
// sigma_c). A parameter without variance (held at nominal, or not determined) correlates with
// nothing but itself.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace fitcal {

// One sigma per parameter: the square roots of the diagonal (a round-off negative variance
// counts as 0).
inline std::vector<double> SigmasOf(const Eigen::MatrixXd& covariance) {
  std::vector<double> sigma(static_cast<std::size_t>(covariance.rows()));
  for (Eigen::Index k = 0; k < covariance.rows(); ++k)
    sigma[k] = std::sqrt(std::max(0.0, covariance(k, k)));
  return sigma;
}

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
