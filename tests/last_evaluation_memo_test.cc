// The memo of a residual block's last two evaluations (fit/last_evaluation_memo.h): a repeated
// request at either point is answered from it bit for bit, any other request is evaluated; and on
// a bounded Ceres solve, where the trust-region minimizer's projected line search evaluates the
// step's end with Jacobians before HandleSuccessfulStep evaluates it again, the memo answers those
// second requests and the solve ends at the same parameters, bit for bit, after the same steps;
// the Jacobian at the solution afterwards (the covariance's) is answered from the older slot.

#include "fit/last_evaluation_memo.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

namespace fitcal {
namespace last_evaluation_memo_test {  // the batch's other files have helpers of these names
namespace {

// y = a exp(b x) + c at one sample, residual y_model - y (Ceres' curve-fitting example, with an
// offset so that a bound can bind).
struct ExponentialResidual {
  ExponentialResidual(double x_in, double y_in) : x(x_in), y(y_in) {}
  template <typename T>
  bool operator()(const T* const p, T* residual) const {
    residual[0] = p[0] * exp(p[1] * x) + p[2] - y;
    return true;
  }
  static ceres::CostFunction* Create(double x, double y) {
    return new ceres::AutoDiffCostFunction<ExponentialResidual, 1, 3>(
        new ExponentialResidual(x, y));
  }
  const double x;
  const double y;
};

// Passes requests on to `cost`, and keeps the point of the last one with Jacobians in `last`:
// what a memo of one evaluation would hold (every block of the solve has the same point).
class LastJacobianPoint : public ceres::CostFunction {
 public:
  LastJacobianPoint(ceres::CostFunction* cost, std::vector<double>* last)
      : cost_(cost), last_(last) {
    set_num_residuals(cost_->num_residuals());
    *mutable_parameter_block_sizes() = cost_->parameter_block_sizes();
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (jacobians != nullptr) last_->assign(parameters[0], parameters[0] + 3);
    return cost_->Evaluate(parameters, residuals, jacobians);
  }

 private:
  std::unique_ptr<ceres::CostFunction> cost_;
  std::vector<double>* last_;
};

struct Samples {
  std::vector<double> x, y;
};

// Samples of 0.8 exp(0.3 x) + 0.1 with seeded noise.
Samples NoisyExponential() {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.02);
  Samples s;
  for (int i = 0; i < 60; ++i) {
    const double x = 0.1 * i;
    s.x.push_back(x);
    s.y.push_back(0.8 * std::exp(0.3 * x) + 0.1 + noise(rng));
  }
  return s;
}

struct Solved {
  std::vector<double> p;
  ceres::Solver::Summary summary;
  int evaluations = 0;  // of the wrapped costs (memo only)
  int answered_from_memo = 0;
  std::vector<double> last_jacobian_point;  // of the solve (memo only)
  ceres::CRSMatrix jacobian_at_solution;    // asked for after the solve, as a covariance does
  int answered_at_solution = 0;
};

Solved SolveBounded(const Samples& s, bool memo) {
  Solved out;
  out.p = {1.0, 0.1, 0.0};
  std::vector<double> last_jacobian_point;
  ceres::Problem problem;
  std::vector<const LastEvaluationMemo*> memos;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    ceres::CostFunction* cost = ExponentialResidual::Create(s.x[i], s.y[i]);
    if (memo) {
      auto* wrapped = new LastEvaluationMemo(new LastJacobianPoint(cost, &last_jacobian_point));
      memos.push_back(wrapped);
      cost = wrapped;
    }
    problem.AddResidualBlock(cost, nullptr, out.p.data());
  }
  // Any bound makes the problem constrained, and Ceres then line-searches every step.
  problem.SetParameterLowerBound(out.p.data(), 2, -1.0);
  problem.SetParameterUpperBound(out.p.data(), 2, 1.0);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  options.gradient_tolerance = 1e-14;
  ceres::Solve(options, &problem, &out.summary);
  for (const LastEvaluationMemo* m : memos) {
    out.evaluations += m->evaluations();
    out.answered_from_memo += m->answered_from_memo();
  }
  out.last_jacobian_point = last_jacobian_point;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, nullptr, nullptr,
                   &out.jacobian_at_solution);
  for (const LastEvaluationMemo* m : memos) out.answered_at_solution += m->answered_from_memo();
  out.answered_at_solution -= out.answered_from_memo;
  return out;
}

TEST(LastEvaluationMemo, ARepeatedRequestIsAnsweredBitForBitAndAnyOtherIsEvaluated) {
  const LastEvaluationMemo memo(ExponentialResidual::Create(1.5, 2.0));
  double p[3] = {0.8, 0.3, 0.1};
  const double* parameters[] = {p};
  double r1 = 0.0, r2 = 0.0, j1[3] = {}, j2[3] = {};
  double* jacobians1[] = {j1};
  double* jacobians2[] = {j2};
  ASSERT_TRUE(memo.Evaluate(parameters, &r1, jacobians1));
  ASSERT_TRUE(memo.Evaluate(parameters, &r2, jacobians2));
  EXPECT_EQ(memo.evaluations(), 1);
  EXPECT_EQ(memo.answered_from_memo(), 1);
  EXPECT_EQ(std::memcmp(&r1, &r2, sizeof r1), 0);
  EXPECT_EQ(std::memcmp(j1, j2, sizeof j1), 0);

  double r3 = 0.0;
  ASSERT_TRUE(memo.Evaluate(parameters, &r3, nullptr));  // residuals only: always evaluated
  EXPECT_EQ(memo.evaluations(), 2);
  double* no_block_jacobian[] = {nullptr};  // another pattern of Jacobians: evaluated
  ASSERT_TRUE(memo.Evaluate(parameters, &r3, no_block_jacobian));
  EXPECT_EQ(memo.evaluations(), 3);
  // The first request is still in the older slot (a one-slot memo held only the last pattern).
  std::fill(j2, j2 + 3, 0.0);
  ASSERT_TRUE(memo.Evaluate(parameters, &r2, jacobians2));
  EXPECT_EQ(memo.evaluations(), 3);
  EXPECT_EQ(memo.answered_from_memo(), 2);
  EXPECT_EQ(std::memcmp(&r1, &r2, sizeof r1), 0);
  EXPECT_EQ(std::memcmp(j1, j2, sizeof j1), 0);

  p[1] = std::nextafter(p[1], 1.0);  // one ulp away: another point, in place of the older slot
  ASSERT_TRUE(memo.Evaluate(parameters, &r2, jacobians2));
  EXPECT_EQ(memo.evaluations(), 4);
  EXPECT_NE(j1[0], j2[0]);
  p[1] = std::nextafter(p[1], 0.0);  // back: the first point is gone from the memo
  ASSERT_TRUE(memo.Evaluate(parameters, &r2, jacobians2));
  EXPECT_EQ(memo.evaluations(), 5);
  EXPECT_EQ(memo.answered_from_memo(), 2);
}

TEST(LastEvaluationMemo, BoundedSolveEndsBitForBitWhereItDidWithoutTheMemoWithFewerEvaluations) {
  const Samples samples = NoisyExponential();
  const Solved plain = SolveBounded(samples, false);
  const Solved memo = SolveBounded(samples, true);
  ASSERT_EQ(plain.summary.termination_type, ceres::CONVERGENCE) << plain.summary.FullReport();
  EXPECT_EQ(memo.summary.iterations.size(), plain.summary.iterations.size());
  EXPECT_EQ(memo.summary.termination_type, plain.summary.termination_type);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(std::memcmp(&memo.p[k], &plain.p[k], sizeof(double)), 0) << k;
  }
  EXPECT_EQ(memo.summary.final_cost, plain.summary.final_cost);
  // Every block is asked once per Ceres evaluation; the memo answered some of them.
  const int blocks = static_cast<int>(samples.x.size());
  const int requests = blocks * (memo.summary.num_residual_evaluations +
                                 memo.summary.num_jacobian_evaluations);
  EXPECT_EQ(memo.evaluations + memo.answered_from_memo, requests);
  // Each successful step's end was evaluated with Jacobians twice (line search, then the step):
  // one of the two is a copy now.
  int successful = 0;
  for (const ceres::IterationSummary& it : memo.summary.iterations) {
    if (it.iteration > 0 && it.step_is_successful) ++successful;
  }
  ASSERT_GT(successful, 2);
  EXPECT_GE(memo.answered_from_memo, blocks * successful);
  // The solve ended on a step it did not take (the function tolerance stopped it after its line
  // search evaluated the candidate with Jacobians): a memo of one evaluation held the candidate,
  // and the solution's Jacobian, asked for as a covariance does, is the older slot's, bit for bit.
  ASSERT_EQ(memo.last_jacobian_point.size(), 3u);
  ASSERT_NE(std::memcmp(memo.last_jacobian_point.data(), memo.p.data(), 3 * sizeof(double)), 0);
  EXPECT_EQ(memo.answered_at_solution, blocks);
  EXPECT_EQ(memo.jacobian_at_solution.values, plain.jacobian_at_solution.values);
}

}  // namespace
}  // namespace last_evaluation_memo_test
}  // namespace fitcal
