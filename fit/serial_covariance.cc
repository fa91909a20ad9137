#include "fit/serial_covariance.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>

#include "odometry/pose_between.h"

namespace fitcal {
namespace {

Pose2d Inverse(const Pose2d& p) { return Between(p, Pose2d{}); }

// The SE(2) adjoint of `pose` in (x, y, theta) coordinates (header).
Eigen::Matrix3d Adjoint(const Pose2d& pose) {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  Eigen::Matrix3d ad;
  ad << c, -s, pose.y, s, c, -pose.x, 0.0, 0.0, 1.0;
  return ad;
}

// Ad(dQ_k^-1): carries an error in the frame at checkpoint k-1 to the frame at k.
Eigen::Matrix3d StepAdjoint(const TrackErrorChain& run, std::size_t k) {
  const Pose2d previous = k == 0 ? Pose2d{} : run.ground_truth_from_start[k - 1];
  return Adjoint(Inverse(Between(previous, run.ground_truth_from_start[k])));
}

// The innovations eps_k^ = e_k - Ad(dQ_k^-1) e_{k-1} of one run (e_0 = 0).
std::vector<Eigen::Vector3d> Innovations(const TrackErrorChain& run) {
  std::vector<Eigen::Vector3d> out;
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < run.error.size(); ++k) {
    out.push_back(run.error[k] - StepAdjoint(run, k) * previous);
    previous = run.error[k];
  }
  return out;
}

}  // namespace

Eigen::MatrixXd RandomWalkScoreCovariance(const std::vector<TrackErrorChain>& runs, int m) {
  // Sigma and Gamma pooled over every run's innovations (header).
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero(), gamma = Eigen::Matrix3d::Zero();
  int count = 0, pairs = 0;
  std::vector<std::vector<Eigen::MatrixXd>> a_of_run;
  for (const TrackErrorChain& run : runs) {
    const std::vector<Eigen::Vector3d> eps = Innovations(run);
    for (std::size_t j = 0; j < eps.size(); ++j) {
      sigma += eps[j] * eps[j].transpose();
      ++count;
      if (j + 1 < eps.size()) {
        gamma += eps[j] * eps[j + 1].transpose();
        ++pairs;
      }
    }
    // A_j = J_j^T D_j + A_{j+1} Ad(dQ_{j+1}^-1), backwards.
    const std::size_t n = run.error.size();
    std::vector<Eigen::MatrixXd> a(n);
    for (std::size_t j = n; j-- > 0;) {
      a[j] = run.jacobian[j].transpose() * run.residual_per_error[j];
      if (j + 1 < n) a[j] += a[j + 1] * StepAdjoint(run, j + 1);
    }
    a_of_run.push_back(std::move(a));
  }
  Eigen::MatrixXd lag0 = Eigen::MatrixXd::Zero(m, m), lag1 = Eigen::MatrixXd::Zero(m, m);
  if (count == 0) return lag0;
  sigma /= count;
  if (pairs > 0) gamma /= pairs;
  for (const std::vector<Eigen::MatrixXd>& a : a_of_run) {
    for (std::size_t j = 0; j < a.size(); ++j) {
      lag0 += a[j] * sigma * a[j].transpose();
      if (j + 1 < a.size()) {
        const Eigen::MatrixXd cross = a[j] * gamma * a[j + 1].transpose();
        lag1 += cross + cross.transpose();
      }
    }
  }
  const Eigen::MatrixXd with_lag1 = lag0 + lag1;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(with_lag1);
  return eigen.eigenvalues().minCoeff() >= 0.0 ? with_lag1 : lag0;
}

Eigen::MatrixXd InverseInformation(const Eigen::MatrixXd& information) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(information,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd& s = svd.singularValues();
  if (s.size() == 0 || !(s(s.size() - 1) > 1e-14 * s(0))) return {};
  return svd.matrixV() * s.cwiseInverse().asDiagonal() * svd.matrixU().transpose();
}

}  // namespace fitcal
