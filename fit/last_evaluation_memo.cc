#include "fit/last_evaluation_memo.h"

#include <algorithm>
#include <cstring>

namespace fitcal {

LastEvaluationMemo::LastEvaluationMemo(ceres::CostFunction* cost) : cost_(cost) {
  set_num_residuals(cost_->num_residuals());
  *mutable_parameter_block_sizes() = cost_->parameter_block_sizes();
  jacobians_.resize(parameter_block_sizes().size());
}

bool LastEvaluationMemo::Remembers(double const* const* parameters, double** jacobians) const {
  if (!valid_ || residuals_.empty()) return false;
  const std::vector<int32_t>& sizes = parameter_block_sizes();
  const double* point = point_.data();
  for (std::size_t b = 0; b < sizes.size(); ++b) {
    if ((jacobians[b] != nullptr) != with_jacobian_[b]) return false;
    // Bitwise: the same doubles, not merely equal ones (0.0 and -0.0 differ in a sign that a
    // cost may carry into its result).
    if (std::memcmp(point, parameters[b], sizes[b] * sizeof(double)) != 0) return false;
    point += sizes[b];
  }
  return true;
}

void LastEvaluationMemo::Remember(double const* const* parameters, const double* residuals,
                                  double** jacobians) const {
  const std::vector<int32_t>& sizes = parameter_block_sizes();
  point_.clear();
  with_jacobian_.assign(sizes.size(), false);
  for (std::size_t b = 0; b < sizes.size(); ++b) {
    point_.insert(point_.end(), parameters[b], parameters[b] + sizes[b]);
    with_jacobian_[b] = jacobians[b] != nullptr;
    if (jacobians[b] != nullptr) {
      jacobians_[b].assign(jacobians[b], jacobians[b] + num_residuals() * sizes[b]);
    }
  }
  residuals_.assign(residuals, residuals + num_residuals());
  valid_ = true;
}

bool LastEvaluationMemo::Evaluate(double const* const* parameters, double* residuals,
                                  double** jacobians) const {
  if (jacobians == nullptr) {
    ++evaluations_;
    return cost_->Evaluate(parameters, residuals, jacobians);
  }
  if (Remembers(parameters, jacobians)) {
    ++answered_from_memo_;
    std::copy(residuals_.begin(), residuals_.end(), residuals);
    for (std::size_t b = 0; b < jacobians_.size(); ++b) {
      if (jacobians[b] == nullptr) continue;
      std::copy(jacobians_[b].begin(), jacobians_[b].end(), jacobians[b]);
    }
    return true;
  }
  ++evaluations_;
  valid_ = false;
  if (!cost_->Evaluate(parameters, residuals, jacobians)) return false;
  Remember(parameters, residuals, jacobians);
  return true;
}

}  // namespace fitcal
