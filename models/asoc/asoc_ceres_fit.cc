#include "models/asoc/asoc_ceres_fit.h"

#include <ceres/ceres.h>

#include <cmath>
#include <stdexcept>

#include "fit/dense_solver_options.h"
#include "odometry/parallel_for.h"

namespace fitcal::asoc {

AlignedAsocRun AlignAsocRun(const RunLog& run) {
  const std::vector<double>& t = run.encoders.t_s;
  const GroundTruthTrack& gt = run.ground_truth;
  if (t.size() < 2 || gt.t_s.empty()) {
    throw std::invalid_argument("run " + run.id + ": too few encoder or ground-truth samples");
  }
  AlignedAsocRun out;
  out.id = run.id;
  out.trajectory = run.trajectory;
  out.repetition = run.repetition;
  const double begin = run.start_pose ? t.front() : std::max(t.front(), gt.t_s.front());
  const double end = std::min(t.back(), gt.t_s.back());
  std::size_t first = 0, last = 0;
  bool any = false;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] < begin || t[k] > end) continue;
    if (!any) first = k;
    last = k;
    any = true;
  }
  if (!any || last <= first) {
    throw std::invalid_argument("run " + run.id + ": encoders and ground truth share no time");
  }
  out.start = run.start_pose && first == 0 ? *run.start_pose : InterpolateGroundTruth(gt, t[first]);
  out.final_ground_truth = InterpolateGroundTruth(gt, t[last]);
  out.samples.assign(run.encoders.samples.begin() + first, run.encoders.samples.begin() + last + 1);
  return out;
}

bool AsocFitOptions::IsValid(std::string* error) const {
  if (!(weights.position_sigma_m > 0.0) || !(weights.heading_sigma_rad > 0.0)) {
    *error = "residual sigmas must be positive";
    return false;
  }
  if (!(relative_bounds > 0.0 && relative_bounds < 1.0) || !(bias_bound_rad > 0.0)) {
    *error = "bounds must be positive (relative_bounds below 1)";
    return false;
  }
  if (max_num_iterations < 1 || num_threads < 0) {
    *error = "max_num_iterations must be >= 1 and num_threads >= 0";
    return false;
  }
  return true;
}

double AsocFinalPoseCf(const Vehicle& vehicle, const std::vector<AlignedAsocRun>& runs) {
  if (runs.empty()) return 0.0;
  const auto p = vehicle.ToArray();
  std::vector<double> cf(runs.size());
  ParallelFor(runs.size(), 0, [&](std::size_t i) {
    double r[3];
    AsocFinalPoseResidual(runs[i], vehicle.pivots, ResidualWeights{})(p.data(), r);
    cf[i] = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  });
  double sum = 0.0;
  for (double v : cf) sum += v;
  return sum / runs.size();
}

AsocFitResult FitAsocCeres(const std::vector<AlignedAsocRun>& training, const Vehicle& start,
                           const AsocFitOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument("AsocFitOptions: " + error);
  if (training.empty()) throw std::invalid_argument("FitAsocCeres: no training runs");
  AsocFitResult result;
  result.estimate = start;
  std::array<double, kNumParameters> params = start.ToArray();
  double* p = params.data();

  ceres::Problem problem;
  for (const AlignedAsocRun& run : training) {
    problem.AddResidualBlock(AsocFinalPoseResidual::Create(run, start.pivots, options.weights),
                             nullptr, p);
  }
  for (int k = 0; k < kNumParameters; ++k) {
    if (k % kParametersPerCastor == kBiasIndex) {
      problem.SetParameterLowerBound(p, k, p[k] - options.bias_bound_rad);
      problem.SetParameterUpperBound(p, k, p[k] + options.bias_bound_rad);
    } else {
      problem.SetParameterLowerBound(p, k, p[k] * (1.0 - options.relative_bounds));
      problem.SetParameterUpperBound(p, k, p[k] * (1.0 + options.relative_bounds));
    }
  }
  const ceres::Solver::Options solver_options =
      DenseSolverOptions(options.max_num_iterations, options.num_threads);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  result.termination = ceres::TerminationTypeToString(summary.termination_type);
  result.message = summary.message;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  bool finite = true;
  for (double v : params) finite = finite && std::isfinite(v);
  result.usable = finite && summary.termination_type == ceres::CONVERGENCE;
  result.estimate.SetFromArray(p);

  const int dof = 3 * static_cast<int>(training.size()) - kNumParameters;
  if (options.compute_covariance && result.usable && dof > 0) {
    const double s2 = 2.0 * summary.final_cost / dof;
    ceres::Covariance::Options cov_options;
    cov_options.algorithm_type = ceres::DENSE_SVD;
    ceres::Covariance covariance(cov_options);
    const std::vector<std::pair<const double*, const double*>> blocks = {{p, p}};
    if (covariance.Compute(blocks, &problem)) {
      double raw[kNumParameters * kNumParameters];
      covariance.GetCovarianceBlock(p, p, raw);
      for (int k = 0; k < kNumParameters; ++k) {
        result.sigma[k] = std::sqrt(std::max(0.0, s2 * raw[k * kNumParameters + k]));
      }
      result.has_covariance = true;
    } else {
      result.covariance_message =
          "covariance is rank deficient: the runs do not determine all 18 "
          "castor parameters";
    }
  } else if (options.compute_covariance) {
    result.covariance_message = dof <= 0 ? "too few runs for a covariance (need more than 6)"
                                         : "no covariance: the fit is not usable";
  }
  return result;
}

}  // namespace fitcal::asoc
