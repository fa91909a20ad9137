#include "fit/ceres_problem.h"

#include <ceres/covariance.h>
#include <ceres/manifold.h>
#include <ceres/sized_cost_function.h>

#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <utility>

#include "odometry/parallel_for.h"

namespace fitcal {

ceres::Solver::Options SolverOptionsFor(const CeresFitOptions& options) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_QR;
  o.trust_region_strategy_type = options.trust_region == CeresTrustRegion::kDogleg
                                     ? ceres::DOGLEG
                                     : ceres::LEVENBERG_MARQUARDT;
  o.max_num_iterations = options.max_num_iterations;
  o.num_threads = ResolveThreadCount(options.num_threads);
  o.function_tolerance = options.function_tolerance;
  o.gradient_tolerance = options.gradient_tolerance;
  o.parameter_tolerance = options.parameter_tolerance;
  o.logging_type = ceres::SILENT;
  return o;
}

namespace {

// A residual with nothing to fit, solved once to make Ceres start its pool.
class ZeroResidual final : public ceres::SizedCostFunction<1, 1> {
 public:
  bool Evaluate(double const* const* /*x*/, double* r, double** jacobians) const override {
    r[0] = 0.0;
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = 1.0;
    return true;
  }
};

// The context with its pool's threads started, all of them, and with every signal blocked. They
// live as long as the process, and a signal delivered to one of them runs its handler beside the
// main thread, which goes on: io/atomic_file.h's cleanup then raced the rename it must come
// before (NothingLostTest.SignalAtEveryStageLeavesThePreviousOutputUntouched). Ceres sizes its
// pool at a solve's num_threads - 1, capped at the hardware's threads, so a solve on one thread
// more than the hardware has starts every thread it will ever have.
ceres::Context* ContextWithItsThreadsStarted() {
  ceres::Context* context = ceres::Context::Create();
  sigset_t all, previous;
  sigfillset(&all);
  pthread_sigmask(SIG_BLOCK, &all, &previous);
  double x = 0.0;
  ceres::Problem::Options problem_options;
  problem_options.context = context;
  ceres::Problem problem(problem_options);
  problem.AddResidualBlock(new ZeroResidual, nullptr, &x);
  ceres::Solver::Options options;
  options.logging_type = ceres::SILENT;
  options.num_threads = ResolveThreadCount(0) + 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return context;
}

}  // namespace

ceres::Problem::Options ProblemOptionsOnSharedContext() {
  // Made once and never destroyed: a fit may still run on another thread while statics go.
  static ceres::Context* const context = ContextWithItsThreadsStarted();
  ceres::Problem::Options options;
  options.context = context;
  return options;
}

std::vector<bool> HoldAtNominal(const Robot& robot, double* p) {
  for (const HeldParameter& h : robot.held) p[h.index] = robot.nominal[h.index];
  return robot.HeldFlags();
}

void BoundModelBlock(const Robot& robot, const std::vector<bool>& fixed, double* p,
                     ceres::Problem* problem) {
  const int n = robot.NumParameters();
  std::vector<int> constant;
  for (int k = 0; k < n; ++k) {
    if (fixed[k]) constant.push_back(k);
    p[k] = std::clamp(p[k], robot.bounds[k].lo, robot.bounds[k].hi);
    problem->SetParameterLowerBound(p, k, robot.bounds[k].lo);
    problem->SetParameterUpperBound(p, k, robot.bounds[k].hi);
  }
  if (static_cast<int>(constant.size()) == n) {
    problem->SetParameterBlockConstant(p);
  } else if (!constant.empty()) {
    problem->SetManifold(p, new ceres::SubsetManifold(n, constant));
  }
}

double SumOfSquares(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& blocks) {
  ceres::Problem::EvaluateOptions options;
  options.apply_loss_function = false;
  options.residual_blocks = blocks;
  double half_sum_of_squares = 0.0;  // Ceres' cost
  problem->Evaluate(options, &half_sum_of_squares, nullptr, nullptr, nullptr);
  return 2.0 * half_sum_of_squares;
}

std::vector<Eigen::MatrixXd> ScaledCovariance(ceres::Problem* problem,
                                              const std::vector<const double*>& blocks, double s2,
                                              bool pseudo_inverse, int num_threads) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.num_threads = ResolveThreadCount(num_threads);
  if (pseudo_inverse) options.null_space_rank = -1;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (const double* b : blocks) pairs.emplace_back(b, b);
  if (!covariance.Compute(pairs, problem)) return {};
  std::vector<Eigen::MatrixXd> out;
  for (const double* b : blocks) {
    const int size = problem->ParameterBlockSize(b);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> raw(size, size);
    covariance.GetCovarianceBlock(b, b, raw.data());
    out.push_back(s2 * raw);
  }
  return out;
}

}  // namespace fitcal
