#include "validation/propagated_uncertainty.h"

#include <ceres/cost_function.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <memory>

namespace fitcal {
namespace {

// The free parameters: not held by the caller nor by the robot's gauge.
std::vector<int> FreeParameters(const Robot& robot, const std::vector<bool>& held) {
  std::vector<bool> fixed = robot.HeldFlags();
  for (std::size_t k = 0; k < held.size() && k < fixed.size(); ++k) fixed[k] = fixed[k] || held[k];
  std::vector<int> free;
  for (std::size_t k = 0; k < fixed.size(); ++k) {
    if (!fixed[k]) free.push_back(static_cast<int>(k));
  }
  return free;
}

}  // namespace

PropagatedUncertainty PropagateFinalPoseUncertainty(const RobotModelInterface& model,
                                                    const std::vector<double>& p,
                                                    const std::vector<AlignedRun>& runs,
                                                    const std::vector<bool>& held) {
  PropagatedUncertainty out;
  const int n = static_cast<int>(p.size());
  const std::vector<int> free = FreeParameters(model.robot(), held);
  const int k = static_cast<int>(free.size());
  const int m = 3 * static_cast<int>(runs.size());
  if (m <= k) {
    out.message = std::to_string(m) + " final-pose residuals for " + std::to_string(k) +
                  " free parameters: no residual degrees of freedom";
    return out;
  }
  Eigen::MatrixXd jacobian(m, n);
  double rss = 0.0;
  Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> block(3, n);
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const std::unique_ptr<ceres::CostFunction> cost(
        model.FinalPoseCost(runs[i], ResidualWeights{}));
    const double* parameters[] = {p.data()};
    double r[3];
    double* jacobians[] = {block.data()};
    if (cost->num_residuals() != 3 || cost->parameter_block_sizes().size() != 1 ||
        !cost->Evaluate(parameters, r, jacobians)) {
      out.message = "run " + runs[i].id + ": the final-pose residual cannot be evaluated here";
      return out;
    }
    jacobian.middleRows(3 * static_cast<Eigen::Index>(i), 3) = block;
    rss += r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  }
  Eigen::MatrixXd j_free(m, k);
  for (int c = 0; c < k; ++c) j_free.col(c) = jacobian.col(free[c]);
  const Eigen::MatrixXd information = j_free.transpose() * j_free;
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(information);
  if (lu.rank() < k) {
    out.message = "the runs do not determine every free parameter at this point (rank " +
                  std::to_string(lu.rank()) + " of " + std::to_string(k) + ")";
    return out;
  }
  const Eigen::MatrixXd cov_free = (rss / static_cast<double>(m - k)) * lu.inverse();
  out.covariance = Eigen::MatrixXd::Zero(n, n);
  out.sigma.assign(n, 0.0);
  for (int a = 0; a < k; ++a) {
    for (int b = 0; b < k; ++b) out.covariance(free[a], free[b]) = cov_free(a, b);
    out.sigma[free[a]] = std::sqrt(std::max(0.0, cov_free(a, a)));
  }
  out.ok = true;
  return out;
}

}  // namespace fitcal
