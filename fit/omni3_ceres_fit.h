#pragma once
// Fits the nine omni3 parameters to the final poses of a set of runs with Ceres (Palacin
// Sec. 2.6): one residual block per run (final_pose_residual.h), autodiff through the replay,
// started from the robot's nominal parameters (Eq. 15) and bounded by its box (Eq. 16).
//
// The objective is the sum over runs of |r|^2 (least squares on the final-pose error); the
// paper's CF (mean of |r|) is reported beside it by final_pose_cost.h. Uncertainty: the Ceres
// covariance of the parameters scaled by the residual variance s^2 = |r|^2 / (3 N - 9).

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "fit/final_pose_cost.h"
#include "fit/final_pose_residual.h"
#include "fit/solver_options.h"
#include "odometry/aligned_run.h"
#include "odometry/robot_description.h"

namespace fitcal {

using Omni3Covariance = Eigen::Matrix<double, omni3::kNumParameters, omni3::kNumParameters>;

struct Omni3FitResult {
  bool usable = false;         // converged to finite parameters; check before using them
  bool stopped_early = false;  // NO_CONVERGENCE at the iteration limit, finite (model_fit.h)
  std::string termination;     // Ceres termination type, e.g. CONVERGENCE
  std::string message;         // Ceres' reason for stopping
  int iterations = 0;
  int num_residual_evaluations = 0;  // evaluations of all runs' residuals
  int num_jacobian_evaluations = 0;  // evaluations of all runs' residuals and Jacobians
  double solve_time_s = 0.0;
  double initial_cost = 0.0;  // Ceres cost: 0.5 sum |r|^2
  double final_cost = 0.0;
  Omni3ParameterArray parameters{};
  std::array<bool, omni3::kNumParameters> at_bound{};
  // Directions the training runs do not determine, held at the nominal (fit/model_fit.h), each
  // described in parameter terms.
  std::vector<std::string> held_directions;
  Omni3ParameterArray unconstrained_parameters{};  // the fit without the holds, when held
  bool unconstrained_usable = false;

  // Uncertainty (when has_covariance): covariance scaled by the residual variance.
  bool has_covariance = false;
  std::string covariance_message;
  double residual_sigma = 0.0;  // sqrt(|r|^2 / (3 N - 9)), in the objective's units
  Omni3Covariance covariance = Omni3Covariance::Zero();
  Omni3ParameterArray sigma{};
  Omni3Covariance correlation = Omni3Covariance::Identity();
};

// Throws std::invalid_argument for invalid options or no runs.
Omni3FitResult FitOmni3Ceres(const std::vector<AlignedRun>& training, const Omni3Robot& robot,
                             const CeresFitOptions& options = {});

}  // namespace fitcal
