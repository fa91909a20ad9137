#pragma once
// A residual block's cost function that remembers its last evaluation with Jacobians and answers
// a repeated request at the same point from it, bit for bit.
//
// Why: on a bounded problem Ceres' trust-region minimizer (2.1, trust_region_minimizer.cc) runs a
// projected Armijo line search before every step, which evaluates the cost and gradient at the
// candidate x + delta (cubic interpolation needs the gradient there); when the full step is taken
// and succeeds, HandleSuccessfulStep evaluates residuals and Jacobians at that same point again.
// Every successful iteration of fitcal's fits thus replayed each run twice with Jacobians at one
// point (Solver::Summary: 10 Jacobian evaluations for 5 iterations). The second is now a copy.
//
// Only a request of the same kind is answered from the memo (residuals and the same Jacobian
// blocks; a residual-only request is always evaluated): the residual-only path of a cost may
// round differently from its Jacobian path, and the minimizer must see exactly the numbers it saw
// before. The memo is per residual block: Ceres evaluates one block in one thread at a time and a
// problem's evaluations follow each other, so no two threads touch it at once.

#include <ceres/cost_function.h>

#include <memory>
#include <vector>

namespace fitcal {

class LastEvaluationMemo : public ceres::CostFunction {
 public:
  // Takes ownership of `cost`.
  explicit LastEvaluationMemo(ceres::CostFunction* cost);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  // How often the wrapped cost was evaluated, and how many requests the memo answered (tests).
  int evaluations() const { return evaluations_; }
  int answered_from_memo() const { return answered_from_memo_; }

 private:
  bool Remembers(double const* const* parameters, double** jacobians) const;
  void Remember(double const* const* parameters, const double* residuals,
                double** jacobians) const;

  std::unique_ptr<ceres::CostFunction> cost_;
  // The last evaluation with Jacobians: the point, which blocks had Jacobians, the values.
  mutable bool valid_ = false;
  mutable std::vector<double> point_;
  mutable std::vector<bool> with_jacobian_;
  mutable std::vector<double> residuals_;
  mutable std::vector<std::vector<double>> jacobians_;
  mutable int evaluations_ = 0;
  mutable int answered_from_memo_ = 0;
};

}  // namespace fitcal
