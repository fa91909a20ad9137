#pragma once
// Identifiability of the nine omni3 parameters from a set of runs: which combinations of
// parameters the final poses (Palacin Eq. 14 residuals) cannot see, and which extra trajectories
// would let them see it (STYLE.md habit 8: what the data cannot determine is said out loud).
//
// Everything is read from the stacked Jacobian J (3 N x 9) of the final-pose residuals of the
// runs at a parameter point. Parameters are measured in relative units so that one number means
// the same for every parameter: R_i and r_i as relative changes (dR/R, dr/r), delta_i in radians
// (a 0.01 rad turn of a wheel and a 1 % change of its radius are changes of the same order):
//   J_rel = J diag(s),  s_k = p_k for R_i and r_i, s_k = 1 rad for delta_i.
// Three symptoms make a problem non-identifiable:
//   - rank deficient: a singular value of J_rel below rank_tolerance * the largest;
//   - ill-conditioned: largest / smallest singular value above max_condition_number;
//   - two parameters correlated beyond max_abs_correlation (correlation of (J^T J)^-1, which does
//     not depend on units).
// The weak directions are the right singular vectors of J_rel whose singular value is below
// largest / max_condition_number (or, when only a correlation fires, the weakest one).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fit/final_pose_cost.h"
#include "fit/final_pose_residual.h"
#include "odometry/aligned_run.h"

namespace fitcal {

using Omni3Vector = Eigen::Matrix<double, omni3::kNumParameters, 1>;

// The stacked Jacobian d r / d p (3 rows per run, in run order) of Omni3FinalPoseResidual.
Eigen::MatrixXd FinalPoseJacobian(const Omni3ParameterArray& p, const std::vector<AlignedRun>& runs,
                                  const ResidualWeights& weights = {}, int num_threads = 0);

// A trajectory the user could add: a motion command (robot frame, Palacin Eq. 1 and Table A1)
// held for duration_s. `kind` groups candidates in the advice ("straight", "counter-clockwise
// curve", ...).
struct CandidateMotion {
  std::string label;
  std::string kind;
  double vx_m_s = 0.0;
  double vy_m_s = 0.0;
  double omega_rad_s = 0.0;
  double duration_s = 0.0;
};

// The noise-free run of a candidate: constant wheel rates M(commanded) v (Eq. 1) sampled every
// period_s, starting at the origin. Its final-pose residual Jacobian does not depend on any
// ground truth.
AlignedRun CandidateRun(const CandidateMotion& motion, const Omni3ParameterArray& commanded,
                        double period_s = 0.01);

struct IdentifiabilityOptions {
  double rank_tolerance = 1e-9;
  // A direction 1000 times less visible than the best one: with the final-pose noise of a few mm
  // and a few tenths of a degree, its uncertainty is ~1000x that of the best-determined
  // combination, i.e. tens of percent of a parameter - not a calibration any more.
  double max_condition_number = 1e3;
  double max_abs_correlation = 0.99;
  bool IsValid(std::string* error) const;
};

struct CorrelatedPair {
  int a = 0;
  int b = 0;
  double correlation = 0.0;
};

struct WeakDirection {
  Omni3Vector direction_rel = Omni3Vector::Zero();  // unit vector in relative units (see above)
  double relative_singular_value = 0.0;             // singular value / largest
  std::string description;                          // words, e.g. "a common change of all R_i"
};

struct IdentifiabilityReport {
  bool identifiable = true;
  bool rank_deficient = false;
  bool ill_conditioned = false;
  double condition_number = 0.0;  // largest / smallest singular value of J_rel (inf if singular)
  Omni3Vector singular_values_rel = Omni3Vector::Zero();
  Eigen::Matrix<double, omni3::kNumParameters, omni3::kNumParameters> correlation;
  std::vector<CorrelatedPair> correlated_pairs;      // |correlation| > max_abs_correlation
  std::vector<std::string> unobservable_parameters;  // parameters lying (>90 %) in the weak space
  std::vector<WeakDirection> weak_directions;
  // Candidate groups (by kind) one repetition of which, added to the runs, removes every symptom;
  // and the labels of each such group.
  std::vector<std::string> fixing_kinds;
  std::vector<std::string> fixing_labels;
};

// `candidates` may be empty (then no advice on trajectories is given). `commanded` are the
// parameters the wheel controller uses for the candidates (the robot's nominal).
IdentifiabilityReport AnalyseIdentifiability(const Eigen::MatrixXd& jacobian,
                                             const Omni3ParameterArray& p,
                                             const std::vector<CandidateMotion>& candidates,
                                             const Omni3ParameterArray& commanded,
                                             const ResidualWeights& weights = {},
                                             const IdentifiabilityOptions& options = {});

// Parameter names in the flat order ("R_a", ..., "delta_c").
std::string ParameterName(int k);

// Human-readable lines: empty when identifiable; otherwise a warning, the weak directions in words
// and the advice on trajectories.
std::vector<std::string> IdentifiabilityLines(const IdentifiabilityReport& report);

}  // namespace fitcal
