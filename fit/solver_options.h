#pragma once
// The settings of a Ceres fit of any model (fit/model_fit.h): trust region, objective, robust
// loss, iteration limit and tolerances, in one options struct with its defaults, validated once
// (IsValid).

#include <ceres/loss_function.h>

#include <string>

#include "models/model_interface.h"

namespace fitcal {

// Ceres' trust-region strategy: Levenberg-Marquardt (default) or Powell's dogleg.
enum class CeresTrustRegion { kLevenbergMarquardt, kDogleg };
// Robust loss on a run's squared residual norm s = |r|^2 (Ceres convention rho(s)), scale in
// the residual's (weighted) units: Huber is quadratic below the scale and linear above it,
// Cauchy grows only logarithmically, so one run with wheel slip cannot drag the fit.
enum class CeresRobustLoss { kNone, kHuber, kCauchy };
// What is minimised over the runs i:
//   kSumOfSquares  sum_i |r_i|^2 (default): smooth, Gauss-Newton converges fast, and the
//                  covariance below is the Gaussian maximum-likelihood one;
//   kSumOfNorms    sum_i |r_i|, exactly N times Palacin Eq. 14's CF, via the loss
//                  rho(s) = 2 sqrt(s) on the squared norm (smoothed by 1e-9 at s = 0). It weighs
//                  every run linearly (L1 over runs), so it is itself robust to an outlying run.
enum class FinalPoseObjective { kSumOfSquares, kSumOfNorms };

const char* ToString(CeresTrustRegion v);
const char* ToString(CeresRobustLoss v);
const char* ToString(FinalPoseObjective v);
// Parse the names above ("none"/"huber"/"cauchy", "squares"/"eq14"); false if
// the text is none of them.
bool ParseCeresRobustLoss(const std::string& text, CeresRobustLoss* out);
bool ParseFinalPoseObjective(const std::string& text, FinalPoseObjective* out);

struct CeresFitOptions {
  ResidualWeights weights;  // default: 1 m counts like 1 rad, as the paper's CF
  CeresTrustRegion trust_region = CeresTrustRegion::kLevenbergMarquardt;
  FinalPoseObjective objective = FinalPoseObjective::kSumOfSquares;
  CeresRobustLoss loss = CeresRobustLoss::kNone;  // only with kSumOfSquares
  double loss_scale = 0.05;  // residual units (m and rad by default): ~5x the clean-run CF
  int max_num_iterations = 100;
  int num_threads = 0;  // 0 = all cores
  double function_tolerance = 1e-12;
  double gradient_tolerance = 1e-14;
  double parameter_tolerance = 1e-12;
  bool compute_covariance = true;

  bool IsValid(std::string* error) const;
};

// The loss Ceres applies to each run's squared residual norm for these options (nullptr: plain
// least squares). Ownership passes to the caller (the Problem).
ceres::LossFunction* MakeLoss(const CeresFitOptions& options);

}  // namespace fitcal
