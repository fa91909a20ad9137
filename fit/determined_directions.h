#pragma once
// Which directions of a model's parameter space do the training runs determine? (Issue "never
// worse": fit what the data determine, hold the rest, and say so in parameter terms.)
//
// The robot's bounds are read as what the user knew before the data: a uniform prior over each
// parameter's box, whose standard deviation is width / sqrt(12). The runs add the information
// H = J^T J / s^2 (J the Jacobian of the weighted final-pose or segment residuals at the fitted
// point, s a robust estimate of the residuals' standard deviation). In the prior's units (every
// free parameter divided by its box sigma) H's eigenvectors are the directions the data see
// independently, and 1 / sqrt(eigenvalue) is the posterior standard deviation along each, as a
// fraction of the prior's. A direction is *determined* when the data shrink that to at most
// kMaxPosteriorFraction (one half: the runs must at least quadruple what the bounds alone know);
// otherwise the fit would move along it by noise and by effects the model lacks, which is how a
// nine-parameter fit to two repetitions lowers its training CF by 90% and raises the held-out
// CF four-fold. Undetermined directions are held at the nominal (fit/model_fit.h).
//
// A track's checkpoints (windows that all start at the run's start) are not independent: each
// carries every error made before it. They are analysed as the stretches between consecutive
// checkpoints (fit/segment_cost.h StretchesBetweenCheckpoints), whose errors are independent, with
// x, y and heading each weighed by its own robust sigma: the information of a track then does not
// grow with its checkpoint count (issue 40; the omni3 joystick run's half fits had moved R_a by
// 24 % along directions counted as determined).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fit/solver_options.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

inline constexpr double kMaxPosteriorFraction = 0.5;

struct UndeterminedDirection {
  // Unit vector over all n parameters in the prior's units (zero on held parameters).
  Eigen::VectorXd prior_units;
  // The same direction in parameter units, scaled to one posterior sigma: moving the parameters
  // together by this much changes the training residuals by one standard deviation.
  Eigen::VectorXd one_sigma_step;
  double posterior_fraction = 0.0;  // posterior sigma / prior sigma along the direction
  double residual_sigma = 0.0;      // s of the analysis that found it (weighted residual units)
  std::string description;          // the combination in parameter terms, and who sees it most
};

struct DirectionAnalysis {
  bool ok = false;            // false: no Jacobian (non-finite residuals) - nothing is held
  double residual_sigma = 0;  // s, in the objective's weighted units
  std::vector<double> posterior_fractions;  // every eigen-direction, ascending information
  std::vector<UndeterminedDirection> undetermined;
  // The conditioning docs/report.md promises to judge, over the free parameters with lengths as
  // relative changes and angles in radians (ParameterInfo::RelativeScale at `p`): the condition
  // number of J^T J (0 when it is singular) and the largest |correlation| of its inverse with the
  // pair's indices into the robot's parameters (-1 when fewer than two are free).
  double condition_number = 0.0;
  double max_abs_correlation = 0.0;
  int correlated_a = -1, correlated_b = -1;
};

// Identifiability thresholds of the report (docs/report.md): beyond either, a parameter moves
// with another or with a combination the runs hardly see.
inline constexpr double kMaxConditionNumber = 1000.0;
inline constexpr double kMaxAbsCorrelation = 0.99;

// The box's standard deviation per parameter (the uniform prior, width / sqrt(12)), 0 for held
// parameters: the unit of UndeterminedDirection::prior_units.
Eigen::VectorXd PriorSigma(const Robot& robot);

// The analysis at `p` over the training runs (final poses, or `segments` when given: one window
// list per run), each run weighed as the fit weighs it (`weights`: one per run; with per-session
// noise levels a noisy session determines less, fit/noise_levels.h).
DirectionAnalysis AnalyseDeterminedDirections(const std::vector<AlignedRun>& training,
                                              const RobotModelInterface& model,
                                              const std::vector<double>& p,
                                              const std::vector<ResidualWeights>& weights,
                                              const std::vector<std::vector<Segment>>* segments,
                                              int num_threads);

// Along `d`, the posterior fraction the training runs would give with `extra` runs added, judged
// at their final poses (Eq. 14, `weights`) with the training residuals' noise s: the data's
// information 1 / f^2 along the direction plus sum_i |J_i (sigma_prior . v)|^2 / s^2. What the
// motion advice (fit/motion_advice.h) asks of a run the user could drive.
double PosteriorFractionWith(const UndeterminedDirection& d, const std::vector<AlignedRun>& extra,
                             const RobotModelInterface& model, const std::vector<double>& p,
                             const ResidualWeights& weights);

}  // namespace fitcal
