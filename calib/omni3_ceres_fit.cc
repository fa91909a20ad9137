#include "calib/omni3_ceres_fit.h"

#include <ceres/ceres.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "odometry/parallel_for.h"

namespace fitcal {

bool CeresFitOptions::IsValid(std::string* error) const {
  if (!(weights.position_sigma_m > 0.0) || !(weights.heading_sigma_rad > 0.0)) {
    *error = "residual sigmas must be positive";
    return false;
  }
  if (max_num_iterations < 1) {
    *error = "max_num_iterations must be at least 1";
    return false;
  }
  if (num_threads < 0) {
    *error = "num_threads must be >= 0";
    return false;
  }
  return true;
}

Omni3FitResult FitOmni3Ceres(const std::vector<AlignedRun>& training, const Omni3Robot& robot,
                             const CeresFitOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("CeresFitOptions: " + error);
  if (training.empty()) throw std::invalid_argument("FitOmni3Ceres: no training runs");

  Omni3FitResult result;
  result.parameters = robot.nominal.ToArray();
  double* p = result.parameters.data();

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (const AlignedRun& run : training) {
    problem.AddResidualBlock(Omni3FinalPoseResidual::Create(run, options.weights), nullptr, p);
  }
  const auto box = robot.ParameterBounds();
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    problem.SetParameterLowerBound(p, k, box[k].lo);
    problem.SetParameterUpperBound(p, k, box[k].hi);
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;  // nine unknowns: dense is exact and cheap
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.num_threads = ResolveThreadCount(options.num_threads);
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.logging_type = ceres::SILENT;

  const auto t0 = std::chrono::steady_clock::now();
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  result.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  result.termination = ceres::TerminationTypeToString(summary.termination_type);
  result.message = summary.message;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  bool finite = true;
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    finite = finite && std::isfinite(p[k]);
    // A parameter within a part per million of the box width of a bound is on it.
    const double tol = 1e-6 * (box[k].hi - box[k].lo);
    result.at_bound[k] = p[k] <= box[k].lo + tol || p[k] >= box[k].hi - tol;
  }
  result.usable = finite && summary.termination_type == ceres::CONVERGENCE;

  const int num_residuals = 3 * static_cast<int>(training.size());
  const int dof = num_residuals - omni3::kNumParameters;
  if (options.compute_covariance && result.usable && dof > 0) {
    result.residual_sigma = std::sqrt(2.0 * summary.final_cost / dof);
    ceres::Covariance::Options cov_options;
    cov_options.algorithm_type = ceres::DENSE_SVD;
    cov_options.num_threads = solver_options.num_threads;
    ceres::Covariance covariance(cov_options);
    const std::vector<std::pair<const double*, const double*>> blocks = {{p, p}};
    if (covariance.Compute(blocks, &problem)) {
      double raw[omni3::kNumParameters * omni3::kNumParameters];
      covariance.GetCovarianceBlock(p, p, raw);
      const double s2 = result.residual_sigma * result.residual_sigma;
      for (int r = 0; r < omni3::kNumParameters; ++r) {
        for (int c = 0; c < omni3::kNumParameters; ++c) {
          result.covariance(r, c) = s2 * raw[r * omni3::kNumParameters + c];
        }
      }
      for (int k = 0; k < omni3::kNumParameters; ++k) {
        result.sigma[k] = std::sqrt(std::max(0.0, result.covariance(k, k)));
      }
      for (int r = 0; r < omni3::kNumParameters; ++r) {
        for (int c = 0; c < omni3::kNumParameters; ++c) {
          const double d = result.sigma[r] * result.sigma[c];
          result.correlation(r, c) = d > 0.0 ? result.covariance(r, c) / d : (r == c ? 1.0 : 0.0);
        }
      }
      result.has_covariance = true;
    } else {
      result.covariance_message =
          "covariance is rank deficient: the runs cannot determine all nine parameters";
    }
  } else if (options.compute_covariance) {
    result.covariance_message = dof <= 0 ? "too few runs for a covariance (need more than 3)"
                                         : "no covariance: the fit is not usable";
  }
  return result;
}

}  // namespace fitcal
