#include "validation/relative_pose_error.h"

#include <algorithm>
#include <cmath>

namespace fitcal {

namespace {

// a^-1 b for planar poses.
Pose2d BetweenWrapped(const Pose2d& a, const Pose2d& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  const double dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, WrapAngle(b.theta - a.theta)};
}

}  // namespace

std::vector<RelativePoseErrorWindow> RelativePoseErrorWindows(
    const std::vector<Pose2d>& ground_truth, const std::vector<Pose2d>& odometry, double length_m) {
  std::vector<RelativePoseErrorWindow> out;
  const std::size_t n = std::min(ground_truth.size(), odometry.size());
  if (n < 2 || !(length_m > 0.0)) return out;
  std::vector<double> s(n, 0.0);  // ground-truth path length from sample 0
  for (std::size_t k = 1; k < n; ++k) {
    s[k] = s[k - 1] + std::hypot(ground_truth[k].x - ground_truth[k - 1].x,
                                 ground_truth[k].y - ground_truth[k - 1].y);
  }
  std::size_t j = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (j < i) j = i;
    while (j < n && s[j] - s[i] < length_m) ++j;
    if (j == n) break;  // no later start reaches the length either
    const Pose2d truth = BetweenWrapped(ground_truth[i], ground_truth[j]);
    const Pose2d odo = BetweenWrapped(odometry[i], odometry[j]);
    const Pose2d e = BetweenWrapped(truth, odo);
    out.push_back({i, j, std::hypot(e.x, e.y) / length_m, std::abs(e.theta) / length_m});
  }
  return out;
}

void AddRelativePoseErrors(const std::vector<Pose2d>& ground_truth,
                           const std::vector<Pose2d>& odometry, double length_m,
                           RelativePoseErrorSum* sum) {
  for (const RelativePoseErrorWindow& w :
       RelativePoseErrorWindows(ground_truth, odometry, length_m)) {
    sum->translation_ratio_sum += w.translation_ratio;
    sum->rotation_rad_per_m_sum += w.rotation_rad_per_m;
    ++sum->windows;
  }
}

std::vector<double> RelativePoseErrorLengths(double median_path_length_m) {
  const double kLengths[] = {100.0, 50.0, 20.0, 10.0, 5.0, 2.0, 1.0, 0.5, 0.25};
  std::vector<double> out;
  for (double l : kLengths) {
    if (2.0 * l <= median_path_length_m && out.size() < 3) out.insert(out.begin(), l);
  }
  return out;
}

}  // namespace fitcal
