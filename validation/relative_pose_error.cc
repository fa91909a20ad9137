#include "validation/relative_pose_error.h"

#include <algorithm>
#include <cmath>

namespace fitcal {

namespace {

// a^-1 b for planar poses, with a's heading as (cos, sin).
Pose2d BetweenWrapped(const Pose2d& a, double c, double s, const Pose2d& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, WrapAngle(b.theta - a.theta)};
}

}  // namespace

RelativePoseErrorRun::RelativePoseErrorRun(const std::vector<Pose2d>& ground_truth,
                                           const std::vector<Pose2d>& odometry)
    : ground_truth_(ground_truth),
      odometry_(odometry),
      n_(std::min(ground_truth.size(), odometry.size())) {
  if (n_ < 2) return;
  path_m_.assign(n_, 0.0);
  for (std::size_t k = 1; k < n_; ++k) {
    // sqrt(dx^2 + dy^2), not std::hypot: steps in metres cannot overflow, so hypot's scaling
    // against it is not needed (speed; every fit scores this; equal up to rounding).
    const double dx = ground_truth[k].x - ground_truth[k - 1].x;
    const double dy = ground_truth[k].y - ground_truth[k - 1].y;
    path_m_[k] = path_m_[k - 1] + std::sqrt(dx * dx + dy * dy);
  }
  ground_truth_heading_.resize(n_);
  odometry_heading_.resize(n_);
  for (std::size_t k = 0; k < n_; ++k) {
    ground_truth_heading_[k] = {std::cos(ground_truth[k].theta), std::sin(ground_truth[k].theta)};
    odometry_heading_[k] = {std::cos(odometry[k].theta), std::sin(odometry[k].theta)};
  }
}

template <typename Visit>
void RelativePoseErrorRun::ForEachWindow(double length_m, Visit&& window) const {
  if (n_ < 2 || !(length_m > 0.0)) return;
  const std::vector<double>& s = path_m_;
  std::size_t j = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    if (j < i) j = i;
    while (j < n_ && s[j] - s[i] < length_m) ++j;
    if (j == n_) break;  // no later start reaches the length either
    const Heading& g = ground_truth_heading_[i];
    const Heading& o = odometry_heading_[i];
    const Pose2d truth = BetweenWrapped(ground_truth_[i], g.c, g.s, ground_truth_[j]);
    const Pose2d odo = BetweenWrapped(odometry_[i], o.c, o.s, odometry_[j]);
    // truth's heading t_j - t_i as (cos, sin) from the stored ones by the difference formulas,
    // cos(t_j - t_i) = c_j c_i + s_j s_i, sin(t_j - t_i) = s_j c_i - c_j s_i: no libm call per
    // window (speed; the wrap by 2 pi changes neither; equal to cos/sin up to rounding).
    const Heading& gj = ground_truth_heading_[j];
    const Pose2d e = BetweenWrapped(truth, gj.c * g.c + gj.s * g.s, gj.s * g.c - gj.c * g.s, odo);
    // |t(E)| as sqrt(x^2 + y^2): metres cannot overflow, so hypot's scaling is not needed (speed).
    window(RelativePoseErrorWindow{i, j, std::sqrt(e.x * e.x + e.y * e.y) / length_m,
                                   std::abs(e.theta) / length_m});
  }
}

std::vector<RelativePoseErrorWindow> RelativePoseErrorRun::Windows(double length_m) const {
  std::vector<RelativePoseErrorWindow> out;
  ForEachWindow(length_m, [&out](const RelativePoseErrorWindow& w) { out.push_back(w); });
  return out;
}

void RelativePoseErrorRun::Add(double length_m, RelativePoseErrorSum* sum) const {
  ForEachWindow(length_m, [sum](const RelativePoseErrorWindow& w) { sum->Add(w); });
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
