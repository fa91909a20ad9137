#include "calib/omni3_ceres_fit.h"

#include <ceres/ceres.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "calib/dense_solver_options.h"
#include "odometry/parallel_for.h"

namespace fitcal {

namespace {

// Palacin Eq. 14 as a loss on the squared norm s = |r|^2: Ceres minimises 0.5 rho(s), so
// rho(s) = 2 sqrt(s) makes a run's cost |r|. Smoothed as 2 (sqrt(s + eps^2) - eps) so that the
// derivative stays finite for a run that fits exactly; eps = 1e-9 residual units (1 nm) is far
// below any CF a real data set reaches.
class SumOfNormsLoss : public ceres::LossFunction {
 public:
  void Evaluate(double s, double rho[3]) const override {
    constexpr double kEps = 1e-9;
    const double a = std::sqrt(s + kEps * kEps);
    rho[0] = 2.0 * (a - kEps);
    rho[1] = 1.0 / a;
    rho[2] = -0.5 / (a * a * a);
  }
};

ceres::LossFunction* MakeLoss(const CeresFitOptions& options) {
  if (options.objective == FinalPoseObjective::kSumOfNorms) return new SumOfNormsLoss;
  switch (options.loss) {
    case CeresRobustLoss::kHuber:
      return new ceres::HuberLoss(options.loss_scale);
    case CeresRobustLoss::kCauchy:
      return new ceres::CauchyLoss(options.loss_scale);
    case CeresRobustLoss::kNone:
      break;
  }
  return nullptr;
}

template <typename E>
struct NamedValue {
  const char* name;
  E value;
};
constexpr NamedValue<CeresTrustRegion> kTrustRegionNames[] = {
    {"lm", CeresTrustRegion::kLevenbergMarquardt}, {"dogleg", CeresTrustRegion::kDogleg}};
constexpr NamedValue<CeresRobustLoss> kLossNames[] = {{"none", CeresRobustLoss::kNone},
                                                      {"huber", CeresRobustLoss::kHuber},
                                                      {"cauchy", CeresRobustLoss::kCauchy}};
constexpr NamedValue<FinalPoseObjective> kObjectiveNames[] = {
    {"squares", FinalPoseObjective::kSumOfSquares}, {"eq14", FinalPoseObjective::kSumOfNorms}};

template <typename E, std::size_t N>
const char* NameOf(const NamedValue<E> (&table)[N], E value) {
  for (const auto& entry : table) {
    if (entry.value == value) return entry.name;
  }
  return "?";
}
template <typename E, std::size_t N>
bool ValueOf(const NamedValue<E> (&table)[N], const std::string& text, E* out) {
  for (const auto& entry : table) {
    if (text == entry.name) {
      *out = entry.value;
      return true;
    }
  }
  return false;
}

}  // namespace

const char* ToString(CeresTrustRegion v) { return NameOf(kTrustRegionNames, v); }
const char* ToString(CeresRobustLoss v) { return NameOf(kLossNames, v); }
const char* ToString(FinalPoseObjective v) { return NameOf(kObjectiveNames, v); }
bool ParseCeresTrustRegion(const std::string& text, CeresTrustRegion* out) {
  return ValueOf(kTrustRegionNames, text, out);
}
bool ParseCeresRobustLoss(const std::string& text, CeresRobustLoss* out) {
  return ValueOf(kLossNames, text, out);
}
bool ParseFinalPoseObjective(const std::string& text, FinalPoseObjective* out) {
  return ValueOf(kObjectiveNames, text, out);
}

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
  if (loss != CeresRobustLoss::kNone && !(loss_scale > 0.0)) {
    *error = "loss_scale must be positive";
    return false;
  }
  if (loss != CeresRobustLoss::kNone && objective == FinalPoseObjective::kSumOfNorms) {
    *error =
        "a robust loss applies to the sum-of-squares objective; the Eq. 14 sum of norms "
        "already weighs each run linearly";
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
    problem.AddResidualBlock(Omni3FinalPoseResidual::Create(run, options.weights),
                             MakeLoss(options), p);
  }
  const auto box = robot.ParameterBounds();
  for (int k = 0; k < omni3::kNumParameters; ++k) {
    problem.SetParameterLowerBound(p, k, box[k].lo);
    problem.SetParameterUpperBound(p, k, box[k].hi);
  }

  DenseSolverTolerances tolerances;
  tolerances.function = options.function_tolerance;
  tolerances.gradient = options.gradient_tolerance;
  tolerances.parameter = options.parameter_tolerance;
  ceres::Solver::Options solver_options =
      DenseSolverOptions(options.max_num_iterations, options.num_threads, tolerances);
  solver_options.trust_region_strategy_type = options.trust_region == CeresTrustRegion::kDogleg
                                                  ? ceres::DOGLEG
                                                  : ceres::LEVENBERG_MARQUARDT;

  const auto t0 = std::chrono::steady_clock::now();
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  result.solve_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  result.termination = ceres::TerminationTypeToString(summary.termination_type);
  result.message = summary.message;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.num_residual_evaluations = summary.num_residual_evaluations;
  result.num_jacobian_evaluations = summary.num_jacobian_evaluations;
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
    // s^2 from the plain sum of squares, whatever loss shaped the objective.
    double sum_of_squares_half = 0.0;
    ceres::Problem::EvaluateOptions evaluate_options;
    evaluate_options.apply_loss_function = false;
    problem.Evaluate(evaluate_options, &sum_of_squares_half, nullptr, nullptr, nullptr);
    result.residual_sigma = std::sqrt(2.0 * sum_of_squares_half / dof);
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
