#include "fit/determined_directions.h"

#include <ceres/cost_function.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>

#include "fit/correlation.h"
#include "fit/segment_cost.h"
#include "odometry/parallel_for.h"
#include "odometry/text_format.h"

namespace fitcal {

namespace {

// One run's residuals and Jacobian (row-major, residuals x n) at p.
struct RunJacobian {
  Eigen::VectorXd residuals;
  Eigen::MatrixXd jacobian;
  bool finite = false;
  bool innovations = false;  // rows: x, y, heading of the stretches between a track's checkpoints
};

RunJacobian EvaluateRun(const ceres::CostFunction& cost, const std::vector<double>& p) {
  const int m = cost.num_residuals();
  const int n = static_cast<int>(p.size());
  RunJacobian out;
  out.residuals.resize(m);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jac(m, n);
  const double* parameters[] = {p.data()};
  double* jacobians[] = {jac.data()};
  out.finite = cost.Evaluate(parameters, out.residuals.data(), jacobians) &&
               out.residuals.allFinite() && jac.allFinite();
  out.jacobian = jac;
  return out;
}

std::vector<RunJacobian> EvaluateRuns(const std::vector<AlignedRun>& training,
                                      const RobotModelInterface& model,
                                      const std::vector<double>& p,
                                      const std::vector<ResidualWeights>& weights,
                                      const std::vector<std::vector<Segment>>* segments,
                                      int num_threads) {
  std::vector<RunJacobian> out(training.size());
  ParallelFor(training.size(), num_threads, [&](std::size_t i) {
    if (segments != nullptr && (*segments)[i].empty()) return;
    // A track's checkpoints are windows from the run's start: each carries every error made before
    // it, so their errors are a random walk along the run (fit/serial_covariance.h), and counting
    // them as independent counts one stretch's error once per later checkpoint - the information of
    // a track then grows with its checkpoint count along the same path, and directions only noise
    // moves look determined (issue 40: the fit of half the omni3 joystick run moved R_a by 24 % and
    // lost to the nominal on the other half). Such windows are analysed as the stretches between
    // the checkpoints, whose errors are independent.
    const std::vector<Segment> stretches =
        segments == nullptr ? std::vector<Segment>{} : StretchesBetweenCheckpoints((*segments)[i]);
    std::unique_ptr<ceres::CostFunction> cost(
        segments == nullptr ? model.FinalPoseCost(training[i], weights[i])
        : stretches.empty() ? model.SegmentCost(training[i], (*segments)[i], weights[i])
                            : model.SegmentCost(training[i], stretches, weights[i]));
    out[i] = EvaluateRun(*cost, p);
    out[i].finite = out[i].finite || out[i].residuals.size() == 0;
    out[i].innovations = !stretches.empty();
  });
  return out;
}

// "R_fl +29 mm with R_rl -28 mm, delta_fl +3.1 deg": the one-sigma step's large components.
std::string DescribeStep(const Robot& robot, const Eigen::VectorXd& prior_units,
                         const Eigen::VectorXd& step) {
  const double largest = prior_units.cwiseAbs().maxCoeff();
  std::string out;
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (std::abs(prior_units[k]) < 0.1 * largest) continue;
    const ParameterInfo& info = robot.parameters[k];
    out += out.empty() ? "" : ", ";
    if (info.unit == ParameterUnit::kAngle) {
      out += StrFormat("%s %+.2g deg", info.name.c_str(), step[k] * 180.0 / M_PI);
    } else if (info.unit == ParameterUnit::kRatio) {
      out += StrFormat("%s %+.2g", info.name.c_str(), step[k]);
    } else {
      out += StrFormat("%s %+.2g mm", info.name.c_str(), step[k] * 1e3);
    }
  }
  return out;
}

// The trajectory whose runs carry the largest share of the information along `direction`.
std::string MostInformativeTrajectory(const std::vector<AlignedRun>& training,
                                      const std::vector<RunJacobian>& runs,
                                      const Eigen::VectorXd& parameter_step, double* share) {
  std::map<std::string, double> by_trajectory;
  double total = 0.0;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    if (runs[i].jacobian.size() == 0) continue;
    const double info = (runs[i].jacobian * parameter_step).squaredNorm();
    by_trajectory[training[i].trajectory] += info;
    total += info;
  }
  std::string best;
  double best_info = -1.0;
  for (const auto& [name, info] : by_trajectory) {
    if (info > best_info) best = name, best_info = info;
  }
  *share = total > 0.0 ? best_info / total : 0.0;
  return best;
}

// A held direction in words: its one-sigma step in parameter terms, how much of the bounds'
// range that is, and which of the data set's own trajectories would determine it.
// How far the direction v (prior units) is along the common scale of every free length (wheels
// and track together: every length times s): |cos| of the angle between them. Under that scale a
// twist's translation grows by s and its rotation does not, so a closed loop ends where it
// started whatever s: final poses of closed loops cannot see it (issue 29).
double AlongCommonScale(const Robot& robot, const Eigen::VectorXd& prior_sigma,
                        const Eigen::VectorXd& v) {
  Eigen::VectorXd scale = Eigen::VectorXd::Zero(v.size());
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (robot.IsHeld(k) || robot.parameters[k].unit != ParameterUnit::kLength) continue;
    scale[k] = robot.nominal[k] / prior_sigma[k];
  }
  const double norm = scale.norm() * v.norm();
  return norm > 0.0 ? std::abs(scale.dot(v)) / norm : 0.0;
}

// Directions this close to the common scale are named as it (cos 0.9: within 26 degrees).
constexpr double kCommonScaleCosine = 0.9;

std::string DescribeDirection(const std::vector<AlignedRun>& training,
                              const std::vector<RunJacobian>& runs, const Robot& robot,
                              const Eigen::VectorXd& v, const Eigen::VectorXd& prior_sigma,
                              double fraction, const Eigen::VectorXd& one_sigma_step) {
  std::string out = DescribeStep(robot, v, one_sigma_step) +
                    " together move the training residuals by only one sigma (" +
                    StrFormat("%.0f%%", 100.0 * std::min(fraction, 1.0)) +
                    " of what the bounds allow)";
  double share = 0.0;
  const std::string trajectory =
      MostInformativeTrajectory(training, runs, prior_sigma.cwiseProduct(v), &share);
  if (!trajectory.empty() && share > 0.0) {
    out += "; more runs like '" + trajectory + "', which sees it most (" +
           StrFormat("%.0f%%", 100.0 * share) + " of its information), would determine it";
  }
  return out;
}

// The residuals' standard deviation, robust to a few gross runs (wheel slip, a wrong ground
// truth) that would otherwise make every direction look undetermined: 1.4826 x the median
// absolute residual (the normal distribution's MAD factor), times sqrt(m / (m - free)) for the
// degrees of freedom the fit used. With no spare degrees of freedom the data cannot tell noise
// from parameters; dividing by one keeps every direction's posterior honest (large).
double RobustSigma(std::vector<double> magnitudes, int num_free) {
  const std::size_t m = magnitudes.size();
  std::nth_element(magnitudes.begin(), magnitudes.begin() + m / 2, magnitudes.end());
  const double mad_sigma = 1.4826 * magnitudes[m / 2];
  const double dof = std::max(1.0, static_cast<double>(m) - num_free);
  return mad_sigma * std::sqrt(static_cast<double>(m) / dof);
}

// Condition number and strongest correlation of J^T J over the free parameters, in relative units
// (see DirectionAnalysis).
void MeasureConditioning(const Robot& robot, const std::vector<double>& p,
                         const std::vector<int>& free, const Eigen::MatrixXd& jtj,
                         DirectionAnalysis* out) {
  const int f = static_cast<int>(free.size());
  Eigen::MatrixXd relative(f, f);
  for (int a = 0; a < f; ++a) {
    for (int b = 0; b < f; ++b) {
      relative(a, b) = robot.parameters[free[a]].RelativeScale(p[free[a]]) * jtj(free[a], free[b]) *
                       robot.parameters[free[b]].RelativeScale(p[free[b]]);
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(relative);
  const double smallest = eigen.eigenvalues().minCoeff(), largest = eigen.eigenvalues().maxCoeff();
  if (f == 0 || !(smallest > 0.0)) return;  // singular: rank deficiency is reported as such
  out->condition_number = largest / smallest;
  const Eigen::MatrixXd correlation = CorrelationOf(relative.inverse());
  for (int a = 0; a < f; ++a) {
    for (int b = a + 1; b < f; ++b) {
      if (std::abs(correlation(a, b)) <= out->max_abs_correlation) continue;
      out->max_abs_correlation = std::abs(correlation(a, b));
      out->correlated_a = free[a];
      out->correlated_b = free[b];
    }
  }
}

}  // namespace

Eigen::VectorXd PriorSigma(const Robot& robot) {
  Eigen::VectorXd sigma = Eigen::VectorXd::Zero(robot.NumParameters());
  for (int k = 0; k < robot.NumParameters(); ++k) {
    if (!robot.IsHeld(k)) sigma[k] = robot.bounds[k].Width() / std::sqrt(12.0);
  }
  return sigma;
}

DirectionAnalysis AnalyseDeterminedDirections(const std::vector<AlignedRun>& training,
                                              const RobotModelInterface& model,
                                              const std::vector<double>& p,
                                              const std::vector<ResidualWeights>& weights,
                                              const std::vector<std::vector<Segment>>* segments,
                                              int num_threads) {
  const Robot& robot = model.robot();
  const int n = robot.NumParameters();
  DirectionAnalysis out;
  const std::vector<RunJacobian> runs =
      EvaluateRuns(training, model, p, weights, segments, num_threads);
  std::vector<double> magnitudes;
  std::array<std::vector<double>, 3> innovation_magnitudes;  // x, y, heading of stretches
  for (const RunJacobian& run : runs) {
    if (!run.finite) return out;
    for (int i = 0; i < run.residuals.size(); ++i) {
      magnitudes.push_back(std::abs(run.residuals[i]));
      if (run.innovations) innovation_magnitudes[i % 3].push_back(std::abs(run.residuals[i]));
    }
  }
  if (magnitudes.empty()) return out;
  out.residual_sigma = RobustSigma(magnitudes, robot.NumFree());
  // A stretch's position and heading errors have noise levels of their own (a heading error made
  // within a stretch shows in its position only as the stretch's length times it): each weighs
  // by its own robust sigma, in the units of s (a row scaled by s / sigma_c), so that the
  // information of a track does not depend on its checkpoint spacing.
  Eigen::Vector3d innovation_scale = Eigen::Vector3d::Ones();
  for (int c = 0; c < 3; ++c) {
    if (innovation_magnitudes[c].empty()) continue;
    const double sigma_c = RobustSigma(innovation_magnitudes[c], robot.NumFree());
    if (sigma_c > 0.0) innovation_scale[c] = out.residual_sigma / sigma_c;
  }
  Eigen::MatrixXd jtj = Eigen::MatrixXd::Zero(n, n);
  for (const RunJacobian& run : runs) {
    if (run.jacobian.size() == 0) continue;
    if (!run.innovations) {
      jtj += run.jacobian.transpose() * run.jacobian;
      continue;
    }
    Eigen::MatrixXd scaled = run.jacobian;
    for (Eigen::Index i = 0; i < scaled.rows(); ++i) scaled.row(i) *= innovation_scale[i % 3];
    jtj += scaled.transpose() * scaled;
  }
  const Eigen::VectorXd prior_sigma = PriorSigma(robot);
  const double s2 = std::max(out.residual_sigma * out.residual_sigma, 1e-300);
  // Over the free parameters only, so that a held parameter's zero column cannot mix into the
  // eigenvectors of the undetermined free directions.
  std::vector<int> free;
  for (int k = 0; k < n; ++k) {
    if (!robot.IsHeld(k)) free.push_back(k);
  }
  const int f = static_cast<int>(free.size());
  Eigen::MatrixXd information(f, f);
  for (int a = 0; a < f; ++a) {
    for (int b = 0; b < f; ++b) {
      information(a, b) = prior_sigma[free[a]] * jtj(free[a], free[b]) * prior_sigma[free[b]] / s2;
    }
  }
  MeasureConditioning(robot, p, free, jtj, &out);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(information);
  for (int i = 0; i < f; ++i) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
    for (int a = 0; a < f; ++a) v[free[a]] = eigen.eigenvectors()(a, i);
    const double fraction = 1.0 / std::sqrt(std::max(eigen.eigenvalues()[i], 1e-300));
    out.posterior_fractions.push_back(fraction);
    if (fraction <= kMaxPosteriorFraction) continue;
    UndeterminedDirection d;
    d.prior_units = v;
    d.posterior_fraction = fraction;
    d.residual_sigma = out.residual_sigma;
    // One posterior sigma along v, capped at the box's own sigma (beyond it the bounds know more).
    d.one_sigma_step = prior_sigma.cwiseProduct(v) * std::min(fraction, 1.0);
    d.description =
        DescribeDirection(training, runs, robot, v, prior_sigma, fraction, d.one_sigma_step);
    if (AlongCommonScale(robot, prior_sigma, v) > kCommonScaleCosine) {
      // Closed loops judged at their end cannot see it; a track can, unless its residuals are
      // too large for it (a tie or a hold the robot does not obey: stop 72's D-F7).
      d.description = "the common scale of wheels and track (" + d.description + "): " +
                      (segments == nullptr
                           ? "closed loops judged at their end cannot see it; add a straight run "
                             "of known length, or fit the track (--residuals track)"
                           : "the tracks' residuals are too large to see it (does the model as "
                             "asked fit these runs?); add a straight run of known length");
    }
    out.undetermined.push_back(d);
  }
  out.ok = true;
  return out;
}

double PosteriorFractionWith(const UndeterminedDirection& d, const std::vector<AlignedRun>& extra,
                             const RobotModelInterface& model, const std::vector<double>& p,
                             const ResidualWeights& weights) {
  // one_sigma_step = sigma_prior . v * min(f, 1) (AnalyseDeterminedDirections).
  const Eigen::VectorXd prior_step =
      d.one_sigma_step / std::max(std::min(d.posterior_fraction, 1.0), 1e-300);
  const double s2 = std::max(d.residual_sigma * d.residual_sigma, 1e-300);
  double information = 1.0 / std::max(d.posterior_fraction * d.posterior_fraction, 1e-300);
  const std::vector<ResidualWeights> alike(extra.size(), weights);
  for (const RunJacobian& run : EvaluateRuns(extra, model, p, alike, nullptr, 1)) {
    if (run.finite && run.jacobian.size() > 0)
      information += (run.jacobian * prior_step).squaredNorm() / s2;
  }
  return 1.0 / std::sqrt(information);
}

}  // namespace fitcal
