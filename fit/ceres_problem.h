#pragma once
// What every Ceres fit of a robot model shares (fit/model_fit.h, fit/effect_fit.h): the solver
// settings of CeresFitOptions, the model's parameter block held and bounded, and the covariance
// of the solution scaled by the residual variance.

#include <ceres/context.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Core>
#include <vector>

#include "fit/solver_options.h"
#include "odometry/robot.h"

namespace fitcal {

// The problems are small (nine to a few dozen unknowns, hundreds of residual blocks), so dense QR
// is exact and cheap; the tolerances (CeresFitOptions) are tight because a fit costs milliseconds
// and the covariance is taken at the end point.
ceres::Solver::Options SolverOptionsFor(const CeresFitOptions& options);

// Problem options on the Ceres context every fit's problem shares (Problem::Options::context):
// without one, each problem made its own, and each solve on more than one thread started and
// joined a new thread pool (62 pools in the 97-run differential drive fit with clock offsets).
// Ceres' ParallelFor lets the calling thread take the work a pool thread has not, so problems
// solved at once share it.
ceres::Problem::Options ProblemOptionsOnSharedContext();

// Sets the robot's held parameters (Robot::held, the gauge) in p to their nominal values and
// returns which they are: the start of every fit.
std::vector<bool> HoldAtNominal(const Robot& robot, double* p);

// Puts the model's parameter block p into the robot's box (Palacin Eq. 16): p is clamped into it
// (Ceres rejects an infeasible start) and every parameter bounded by it; the parameters in
// `fixed` (held, or fixed on a bound by an active set) stay constant.
void BoundModelBlock(const Robot& robot, const std::vector<bool>& fixed, double* p,
                     ceres::Problem* problem);

// |r|^2 over `blocks` without the loss: the residual variance is taken on the data, whatever
// robust loss shaped the objective.
double SumOfSquares(ceres::Problem* problem, const std::vector<ceres::ResidualBlockId>& blocks);

// Ceres' covariance of each parameter block with itself at the problem's current point, scaled
// by s2 = |r|^2 / dof, the caller's residual variance (its residuals, its degrees of freedom):
// one matrix per block, in ambient coordinates (a parameter held by a SubsetManifold gets zero
// rows and columns). Empty when Ceres cannot invert the information: with `pseudo_inverse` it
// truncates the directions the data do not determine instead (Moore-Penrose), for fits whose
// candidates may alias and are reported so rather than refused.
std::vector<Eigen::MatrixXd> ScaledCovariance(ceres::Problem* problem,
                                              const std::vector<const double*>& blocks, double s2,
                                              bool pseudo_inverse, int num_threads);

}  // namespace fitcal
