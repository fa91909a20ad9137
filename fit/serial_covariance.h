#pragma once
// The covariance of a track fit (fit/track_residual.h) whose checkpoint errors along a run are
// not independent: each checkpoint's pose from the run's start carries every error made before
// it, so the errors of one run are a random walk in its checkpoints. Treating them as independent
// (s^2 (J^T J)^-1) counts one run's drift once per checkpoint: on an independent simulation of a
// differential drive (tests/independent_sim/) the wheel separation sat 3-12 of those sigmas from
// the truth.
//
// Model. With Q_k the ground truth's and P_k the odometry's pose at checkpoint k relative to the
// run's start, the checkpoint error delta_k = Log(Q_k^-1 P_k) (to first order the track
// residual's e_k: position error in the ground truth's frame at k, heading error) obeys, for
// small errors,
//   delta_k = Ad(dQ_k^-1) delta_{k-1} + eps_k,   dQ_k = Q_{k-1}^-1 Q_k,   delta_0 = 0,
// where eps_k = Log(dQ_k^-1 dP_k) is the error the odometry made between checkpoints k-1 and k
// in the frame at k, and Ad(R, t) = [[R, (t_y, -t_x)^T], [0, 1]] the SE(2) adjoint (x, y, theta).
// So delta_k = sum_{j<=k} L_kj eps_j with L_kj the adjoint carrying frame j to frame k: a heading
// error made early rotates everything after it. The innovations eps_j are the independent
// quantities (odometry errors over disjoint stretches of path), up to the ground truth's own
// noise at the checkpoints, which makes neighbours correlate (a moving average of order 1).
//
// Score covariance. With residuals r_k = D_k e_k (D_k: the residual's weights and loss factor at
// the solution, taken as constant) and J_k = dr_k / d(parameters, clock offsets), the fit's score
// is g = sum_k J_k^T r_k = sum_j A_j eps_j with A_j = sum_{k>=j} J_k^T D_k L_kj (one backward
// pass: A_j = J_j^T D_j + A_{j+1} Ad(dQ_{j+1}^-1)). Its covariance, with Sigma = E[eps eps^T] and
// Gamma = E[eps_j eps_{j+1}^T] estimated from the innovations of all runs (eps_j^ from the
// errors at the solution),
//   M = sum_runs sum_j A_j Sigma A_j^T + A_j Gamma A_{j+1}^T + A_{j+1} Gamma^T A_j^T.
// The lag-1 terms remove the ground truth's noise, which enters two neighbouring innovations with
// opposite signs; when they would make M indefinite (a short data set) they are dropped, which
// errs on the wide side. The parameters' covariance is the sandwich H^-1 M H^-1 (H = J^T J, the
// Gauss-Newton information of the same residuals): it needs no residual variance s^2.

#include <Eigen/Core>
#include <vector>

#include "odometry/pose2.h"

namespace fitcal {

// One run's checkpoints (k = 1..K, in order) at the solution.
struct TrackErrorChain {
  std::vector<Eigen::MatrixXd> jacobian;         // 3 x m: dr_k / d(every estimated unknown)
  std::vector<Eigen::Matrix3d> residual_per_error;  // D_k: dr_k / de_k
  std::vector<Eigen::Vector3d> error;            // e_k: x, y (m, frame of Q_k), theta (rad)
  std::vector<Pose2d> ground_truth_from_start;   // Q_k
};

// M of the header (m x m) over `runs`; empty runs are skipped.
Eigen::MatrixXd RandomWalkScoreCovariance(const std::vector<TrackErrorChain>& runs, int m);

// H^-1 for a symmetric positive definite H (m x m), by SVD; empty when H is singular to within a
// reciprocal condition number of 1e-14 (Ceres' DENSE_SVD default).
Eigen::MatrixXd InverseInformation(const Eigen::MatrixXd& information);

}  // namespace fitcal
