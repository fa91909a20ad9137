#pragma once
// Residual structure against covariates of the runs: what the repetitions
// hide. The lack-of-fit test (residual_analysis.h) takes the scatter between repetitions of a
// trajectory as its noise floor, so an effect that differs from one repetition to the next (wear
// or warming over a session, anything tied to the world frame when each run starts at another
// heading) lands in that floor and is invisible to it. Here the scatter itself is tested for
// dependence on what differs between the runs.
//
// Response: y_i, the final-pose error of run i in its start frame (m, m, rad). Groups: the
// trajectories with at least two repetitions (the repetitions' deviations d_i = y_i - mean_g y);
// without repetitions, all runs as one group. The deviations are whitened by their pooled
// covariance S = sum d d^T / D, D = sum_g (n_g - 1): z_i = S^-1/2 d_i (r <= 3 components).
//
// A covariate c (one value, or the cos/sin pair of a direction) enters through two kinds of
// alternatives, both centred in the group (c~ = c - mean_g c), for every column of c:
//   - a fitted parameter that drifts with c:  d_i = c~_i J_i delta   (J_i = d y_i / d(parameters),
//     residual_analysis.h; wear changes a radius, a carpet's pile direction scales the speed: the
//     same parameter change shows differently in each trajectory, J_i carries how);
//   - an additive error that drifts with c:   d_i = c~_i beta       (beta in the start frame).
// Least squares over all runs gives SS_reg = b^T A^+ b (A = sum X_i^T X_i, b = sum X_i^T z_i,
// X_i = S^-1/2 [c~_i J_i, c~_i I]); with q the rank of A and SS_tot = sum |z_i|^2,
//   F = (SS_reg / q) / ((SS_tot - SS_reg) / (r D' - q)),
// D' = D, less the fitted parameters' share (k / r) when all runs form one group (their residuals
// then carry the fit). A covariate that does not vary within the groups is not tested there.
// p is a permutation p: the fraction of 1999 reassignments of the alternatives among the runs of
// each group (seeded, reproducible) whose SS_reg reaches the observed one, (1 + count) / 2000.
// Under "no dependence" the runs of a group are exchangeable, whatever the noise level of each
// trajectory; the F(q, r D' - q) reference assumes one level for all and read clean data with
// four repetitions as structure in 3 of 12 seeds.
//
// Multiple testing: Holm's step-down over the covariates tested (family-wise error <= alpha):
// sorted p_(1) <= ... <= p_(m), reject while p_(j) < alpha / (m - j + 1).
//
// Covariates: run order within the session (the encoder clock's start time when the logs share a
// session clock, else the repetition number), world-frame direction of travel (cos, sin of the
// start heading + the robot-frame direction of motion), distance travelled, speed, turning
// direction, and the absolute wheel angle when the logs carry it (cumulative counts,
// TrackRun::start_wheel_angle_rad). The wheel angle changes during a run, so its alternative is
// not c~ times something but an error periodic in each wheel's revolution,
//   d_i = (G_i - mean_g G) beta,   G_i = d y_i / d(a_j, b_j)  (residual_analysis.h),
// w_j' = w_j (1 + a_j cos A_j + b_j sin A_j), A_j wheel j's absolute angle: an eccentric wheel
// r(A) = r0 (1 + e cos(A - A0)) to first order. Runs that start at the same wheel angles share
// G_i, so it is tested only where the start angles differ between repetitions.
// A covariate whose within-group spread is below its resolution (1 mrad of direction, 1 mm,
// 0.1 mm/s) is not tested: data sets rebased to start every run at heading 0 have no world-frame
// direction, whatever rounding leaves in it.

#include <string>
#include <vector>

#include "diagnosis/residual_analysis.h"

namespace fitcal {

struct CovariateTest {
  std::string name;  // "run order within the session", ...
  bool tested = false;
  std::string why_not;  // when not tested
  double f = 0.0, df1 = 0.0, df2 = 0.0, p_value = 1.0;
  double holm_threshold = 0.0;  // alpha / (m - rank + 1), rank of p among the tested
  bool significant = false;
  bool direction = false;  // a cos/sin pair: the residual "depends on" it, else "drifts with" it
};

struct CovariateStructure {
  double alpha = 0.01;              // family-wise (Holm)
  bool within_repetitions = false;  // groups = trajectories with repetitions
  std::vector<CovariateTest> tests;
  bool any_significant = false;
};

// Throws nothing; a test that the data cannot carry is marked not tested with the reason.
CovariateStructure AnalyzeCovariates(const ResidualAnalysis& analysis, double alpha = 0.01);

// "unexplained: the residual drifts with run order within the session (F = ..., p = ...)".
std::string CovariateFinding(const CovariateTest& test);
// Markdown table with the multiple-testing control stated.
std::string FormatCovariateStructure(const CovariateStructure& structure);

}  // namespace fitcal
