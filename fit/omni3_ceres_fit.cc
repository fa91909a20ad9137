#include "fit/omni3_ceres_fit.h"

#include <ceres/ceres.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "fit/model_fit.h"
#include "models/omni3/omni3_robot_model.h"
#include "odometry/parallel_for.h"

namespace fitcal {

Omni3FitResult FitOmni3Ceres(const std::vector<AlignedRun>& training, const Omni3Robot& robot,
                             const CeresFitOptions& options) {
  ModelFitOptions model_options;
  model_options.ceres = options;
  const ModelFitResult fit = FitModel(training, *Omni3ModelOf(robot), model_options);
  Omni3FitResult result;
  result.usable = fit.usable;
  result.stopped_early = fit.stopped_early;
  result.termination = fit.termination;
  result.message = fit.message;
  result.iterations = fit.iterations;
  result.num_residual_evaluations = fit.num_residual_evaluations;
  result.num_jacobian_evaluations = fit.num_jacobian_evaluations;
  result.solve_time_s = fit.solve_time_s;
  result.initial_cost = fit.initial_cost;
  result.final_cost = fit.final_cost;
  std::copy(fit.parameters.begin(), fit.parameters.end(), result.parameters.begin());
  std::copy(fit.at_bound.begin(), fit.at_bound.end(), result.at_bound.begin());
  for (const UndeterminedDirection& d : fit.held_directions) {
    result.held_directions.push_back(d.description);
  }
  if (!fit.held_directions.empty()) {
    std::copy(fit.unconstrained_parameters.begin(), fit.unconstrained_parameters.end(),
              result.unconstrained_parameters.begin());
    result.unconstrained_usable = fit.unconstrained_usable;
  }
  result.has_covariance = fit.has_covariance;
  result.residual_sigma = fit.residual_sigma;
  if (fit.has_covariance) {
    result.covariance = fit.covariance;
    std::copy(fit.sigma.begin(), fit.sigma.end(), result.sigma.begin());
    result.correlation = fit.correlation;
  } else {
    // The omni3 wording: nine parameters, no gauge held.
    result.covariance_message =
        fit.covariance_message ==
                "covariance is rank deficient: the runs cannot determine all "
                "free parameters"
            ? "covariance is rank deficient: the runs cannot determine all nine parameters"
            : fit.covariance_message;
  }
  return result;
}

}  // namespace fitcal
