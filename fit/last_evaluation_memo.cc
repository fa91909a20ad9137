#include "fit/last_evaluation_memo.h"

#include <algorithm>
#include <cstring>

namespace fitcal {

LastEvaluationMemo::LastEvaluationMemo(ceres::CostFunction* cost) : cost_(cost) {
  set_num_residuals(cost_->num_residuals());
  *mutable_parameter_block_sizes() = cost_->parameter_block_sizes();
  for (Evaluation& e : remembered_) e.jacobians.resize(parameter_block_sizes().size());
}

bool LastEvaluationMemo::Remembers(const Evaluation& e, double const* const* parameters,
                                   double** jacobians) const {
  if (!e.valid || e.residuals.empty()) return false;
  const std::vector<int32_t>& sizes = parameter_block_sizes();
  const double* point = e.point.data();
  for (std::size_t b = 0; b < sizes.size(); ++b) {
    if ((jacobians[b] != nullptr) != e.with_jacobian[b]) return false;
    // Bitwise: the same doubles, not merely equal ones (0.0 and -0.0 differ in a sign that a
    // cost may carry into its result).
    if (std::memcmp(point, parameters[b], sizes[b] * sizeof(double)) != 0) return false;
    point += sizes[b];
  }
  return true;
}

void LastEvaluationMemo::Remember(double const* const* parameters, const double* residuals,
                                  double** jacobians) const {
  Evaluation& e = remembered_[older_];
  older_ = 1 - older_;
  const std::vector<int32_t>& sizes = parameter_block_sizes();
  e.point.clear();
  e.with_jacobian.assign(sizes.size(), false);
  for (std::size_t b = 0; b < sizes.size(); ++b) {
    e.point.insert(e.point.end(), parameters[b], parameters[b] + sizes[b]);
    e.with_jacobian[b] = jacobians[b] != nullptr;
    if (jacobians[b] != nullptr) {
      e.jacobians[b].assign(jacobians[b], jacobians[b] + num_residuals() * sizes[b]);
    }
  }
  e.residuals.assign(residuals, residuals + num_residuals());
  e.valid = true;
}

bool LastEvaluationMemo::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  if (jacobians == nullptr) {
    ++evaluations_;
    return cost_->Evaluate(parameters, residuals, jacobians);
  }
  for (const Evaluation& e : remembered_) {
    if (!Remembers(e, parameters, jacobians)) continue;
    ++answered_from_memo_;
    std::copy(e.residuals.begin(), e.residuals.end(), residuals);
    for (std::size_t b = 0; b < e.jacobians.size(); ++b) {
      if (jacobians[b] == nullptr) continue;
      std::copy(e.jacobians[b].begin(), e.jacobians[b].end(), jacobians[b]);
    }
    return true;
  }
  ++evaluations_;
  // A failed evaluation leaves nothing behind; the slots hold what the cost gave at their points.
  if (!cost_->Evaluate(parameters, residuals, jacobians)) return false;
  Remember(parameters, residuals, jacobians);
  return true;
}

}  // namespace fitcal
