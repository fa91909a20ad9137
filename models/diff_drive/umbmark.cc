#include "models/diff_drive/umbmark.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace fitcal::umbmark {

namespace {

// Weighted least squares for (alpha, kappa) from the first-order errors (header):
//   CW:  x = -2 L alpha - 2 L^2 kappa,   y = -2 L alpha - 2 L^2 kappa
//   CCW: x = -2 L alpha + 2 L^2 kappa,   y = +2 L alpha - 2 L^2 kappa
// each run weighted 1 / (runs in its direction).
Eigen::Vector2d SolveAlphaKappa(const std::vector<SquareReturnError>& runs, int num_cw,
                                int num_ccw) {
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  for (const SquareReturnError& run : runs) {
    const double l = run.side_m;
    const double w = 1.0 / (run.clockwise ? num_cw : num_ccw);
    const double s = run.clockwise ? 1.0 : -1.0;  // sign of the kappa term in x
    const Eigen::Vector2d row_x(-2.0 * l, -2.0 * l * l * s);
    const Eigen::Vector2d row_y = run.clockwise ? Eigen::Vector2d(-2.0 * l, -2.0 * l * l)
                                                : Eigen::Vector2d(2.0 * l, -2.0 * l * l);
    normal += w * (row_x * row_x.transpose() + row_y * row_y.transpose());
    rhs += w * (row_x * run.x_m + row_y * run.y_m);
  }
  return normal.ldlt().solve(rhs);
}

}  // namespace

std::optional<Correction> Correct(const std::vector<SquareReturnError>& runs,
                                  const DiffDriveGeometry& nominal) {
  Correction c;
  double side_cw = 0.0, side_ccw = 0.0;
  for (const SquareReturnError& run : runs) {
    if (!(run.side_m > 0.0)) return std::nullopt;
    (run.clockwise ? c.num_cw : c.num_ccw) += 1;
    (run.clockwise ? side_cw : side_ccw) += run.side_m;
  }
  if (c.num_cw == 0 || c.num_ccw == 0) return std::nullopt;
  c.side_m = 0.5 * (side_cw / c.num_cw + side_ccw / c.num_ccw);
  const Eigen::Vector2d alpha_kappa = SolveAlphaKappa(runs, c.num_cw, c.num_ccw);
  c.alpha_rad = alpha_kappa[0];
  c.beta_rad = alpha_kappa[1] * c.side_m;
  // Borenstein & Feng Eq. 12-13 with 1/R = sin(beta/2) / (L/2) (finite for beta = 0):
  // E_d = (R + b/2) / (R - b/2) = (1 + b/(2R)) / (1 - b/(2R)).
  const double half_b_over_r = nominal.separation_m * std::sin(0.5 * c.beta_rad) / c.side_m;
  if (!(std::abs(half_b_over_r) < 1.0) || !(std::abs(c.alpha_rad) < 0.5 * M_PI)) {
    return std::nullopt;
  }
  c.e_d = (1.0 + half_b_over_r) / (1.0 - half_b_over_r);
  // Eq. 17: E_b = 90 deg / (90 deg - alpha), in radians.
  c.e_b = (0.5 * M_PI) / (0.5 * M_PI - c.alpha_rad);
  c.corrected.separation_m = c.e_b * nominal.separation_m;
  // r_R' / r_L' = E_d r_R / r_L with r_R' + r_L' = r_R + r_L (Eq. 14-15 for equal radii).
  const double sum = nominal.r_right_m + nominal.r_left_m;
  const double k = sum / (c.e_d * nominal.r_right_m + nominal.r_left_m);
  c.corrected.r_right_m = k * c.e_d * nominal.r_right_m;
  c.corrected.r_left_m = k * nominal.r_left_m;
  return c;
}

std::optional<SquareReturnError> MeasureSquare(const RobotModelInterface& model,
                                               const std::vector<double>& p,
                                               const AlignedRun& run) {
  if (run.samples.empty()) return std::nullopt;
  // The odometry path in the start frame: x along the start heading.
  const double c0 = std::cos(run.start.theta), s0 = std::sin(run.start.theta);
  const auto to_start_frame = [&run, c0, s0](double wx, double wy, double* x, double* y) {
    *x = c0 * (wx - run.start.x) + s0 * (wy - run.start.y);
    *y = -s0 * (wx - run.start.x) + c0 * (wy - run.start.y);
  };
  // The side: a quarter of the odometry's path length (four legs; corners turned on the spot add
  // nothing). Unlike the path's extent it does not grow with the distortion being measured.
  double path_m = 0.0;
  Pose2d previous = run.start;
  const Pose2d odometry = model.Replay(p.data(), run.samples, 0, run.samples.size(), run.start,
                                       [&](std::size_t, const Pose2d& pose) {
                                         path_m +=
                                             std::hypot(pose.x - previous.x, pose.y - previous.y);
                                         previous = pose;
                                       });
  const double turn_rad = odometry.theta - run.start.theta;
  // Not one lap of a square.
  if (!(std::abs(turn_rad) >= 1.25 * M_PI && std::abs(turn_rad) <= 2.5 * M_PI)) return std::nullopt;
  SquareReturnError e;
  e.clockwise = turn_rad < 0.0;
  e.side_m = 0.25 * path_m;
  double end_x, end_y;
  to_start_frame(odometry.x, odometry.y, &end_x, &end_y);
  // The odometry path does not close.
  if (!(e.side_m > 0.0) || std::hypot(end_x, end_y) > 0.25 * e.side_m) return std::nullopt;
  double gt_x, gt_y;
  to_start_frame(run.final_ground_truth.x, run.final_ground_truth.y, &gt_x, &gt_y);
  e.x_m = gt_x - end_x;
  e.y_m = gt_y - end_y;
  return e;
}

}  // namespace fitcal::umbmark
