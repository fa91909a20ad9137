#include "validation/relative_pose_error.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace fitcal {

namespace {

// a^-1 b for planar poses, with a's heading as (cos, sin).
Pose2d BetweenWrapped(const Pose2d& a, double c, double s, const Pose2d& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, WrapAngle(b.theta - a.theta)};
}

}  // namespace

RelativePoseErrorTruth::RelativePoseErrorTruth(std::vector<Pose2d> ground_truth)
    : poses_(std::move(ground_truth)), path_m_(poses_.size(), 0.0) {
  const std::vector<Pose2d>& g = poses_;
  for (std::size_t k = 1; k < g.size(); ++k) {
    // sqrt(dx^2 + dy^2), not std::hypot: steps in metres cannot overflow, so hypot's scaling
    // against it is not needed (speed; every fit scores this; equal up to rounding).
    const double dx = g[k].x - g[k - 1].x, dy = g[k].y - g[k - 1].y;
    path_m_[k] = path_m_[k - 1] + std::sqrt(dx * dx + dy * dy);
  }
  heading_.reserve(g.size());
  for (const Pose2d& q : g) heading_.push_back({std::cos(q.theta), std::sin(q.theta)});
}

RelativePoseErrorRun::RelativePoseErrorRun(const RelativePoseErrorTruth& truth,
                                           const std::vector<Pose2d>& odometry)
    : truth_(truth), odometry_(odometry), n_(std::min(truth.poses_.size(), odometry.size())) {
  if (n_ < 2) return;
  odometry_heading_.reserve(n_);
  for (std::size_t k = 0; k < n_; ++k) {
    odometry_heading_.push_back({std::cos(odometry[k].theta), std::sin(odometry[k].theta)});
  }
}

template <typename Visit>
void RelativePoseErrorRun::ForEachWindow(double length_m, Visit&& window) const {
  if (n_ < 2 || !(length_m > 0.0)) return;
  const std::vector<double>& s = truth_.path_m_;
  const std::vector<Pose2d>& ground_truth = truth_.poses_;
  std::size_t j = 0;
  for (std::size_t i = 0; i < n_; ++i) {
    if (j < i) j = i;
    while (j < n_ && s[j] - s[i] < length_m) ++j;
    if (j == n_) break;  // no later start reaches the length either
    const RelativePoseErrorTruth::Heading& g = truth_.heading_[i];
    const RelativePoseErrorTruth::Heading& o = odometry_heading_[i];
    const Pose2d truth = BetweenWrapped(ground_truth[i], g.c, g.s, ground_truth[j]);
    const Pose2d odo = BetweenWrapped(odometry_[i], o.c, o.s, odometry_[j]);
    // truth's heading t_j - t_i as (cos, sin) from the stored ones by the difference formulas,
    // cos(t_j - t_i) = c_j c_i + s_j s_i, sin(t_j - t_i) = s_j c_i - c_j s_i: no libm call per
    // window (speed; the wrap by 2 pi changes neither; equal to cos/sin up to rounding).
    const RelativePoseErrorTruth::Heading& gj = truth_.heading_[j];
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
