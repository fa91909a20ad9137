#pragma once
// The Ceres solver settings every fitcal fit shares. The problems are small (nine to a few dozen
// unknowns, hundreds of residual blocks), so dense QR is exact and cheap; the tolerances are tight
// because a fit costs milliseconds and the covariance is taken at the end point.

#include <ceres/solver.h>

#include "odometry/parallel_for.h"

namespace fitcal {

struct DenseSolverTolerances {
  double function = 1e-12;
  double gradient = 1e-14;
  double parameter = 1e-12;
};

inline ceres::Solver::Options DenseSolverOptions(int max_num_iterations, int num_threads,
                                                 const DenseSolverTolerances& tol = {}) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_QR;
  o.max_num_iterations = max_num_iterations;
  o.num_threads = ResolveThreadCount(num_threads);
  o.function_tolerance = tol.function;
  o.gradient_tolerance = tol.gradient;
  o.parameter_tolerance = tol.parameter;
  o.logging_type = ceres::SILENT;
  return o;
}

}  // namespace fitcal
