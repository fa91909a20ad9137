#pragma once
// A residual block's cost function that remembers its last two evaluations with Jacobians and
// answers a repeated request at either point from them, bit for bit.
//
// Why: on a bounded problem Ceres' trust-region minimizer (2.1, trust_region_minimizer.cc) runs a
// projected Armijo line search before every step, which evaluates the cost and gradient at the
// candidate x + delta (cubic interpolation needs the gradient there); when the full step is taken
// and succeeds, HandleSuccessfulStep evaluates residuals and Jacobians at that same point again.
// Every successful iteration of fitcal's fits thus replayed each run twice with Jacobians at one
// point (Solver::Summary: 10 Jacobian evaluations for 5 iterations). The second is now a copy.
// Why two: a solve usually ends on a step it does not take (its line search evaluated the
// candidate with Jacobians, then the function tolerance stopped it), so the evaluation at the
// solution is the one before the last; the covariance's Jacobian there (fit/ceres_problem.h
// ScaledCovariance on the solved problem) is then a copy too (not after two rejected steps).
//
// Only a request of the same kind is answered from the memo (residuals and the same Jacobian
// blocks; a residual-only request is always evaluated): the residual-only path of a cost may
// round differently from its Jacobian path, and the minimizer must see exactly the numbers it saw
// before. The memo is per residual block: Ceres evaluates one block in one thread at a time and a
// problem's evaluations follow each other, so no two threads touch it at once.

#include <ceres/cost_function.h>

#include <array>
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
  // One evaluation with Jacobians: the point, which blocks had Jacobians, the values.
  struct Evaluation {
    bool valid = false;
    std::vector<double> point;
    std::vector<bool> with_jacobian;
    std::vector<double> residuals;
    std::vector<std::vector<double>> jacobians;
  };
  bool Remembers(const Evaluation& e, double const* const* parameters, double** jacobians) const;
  void Remember(double const* const* parameters, const double* residuals, double** jacobians) const;

  std::unique_ptr<ceres::CostFunction> cost_;
  mutable std::array<Evaluation, 2> remembered_;
  mutable int older_ = 0;  // the slot the next evaluation replaces
  mutable int evaluations_ = 0;
  mutable int answered_from_memo_ = 0;
};

}  // namespace fitcal
