#pragma once

#include <cmath>

#include "odometry/pose2.h"

namespace fitcal {

// Between (below) with a's c = cos(a.theta) and s = sin(a.theta) given: many poses b in one
// frame a form them once (the same numbers as Between's).
template <typename T>
Pose2<T> BetweenRotated(const Pose2<T>& a, const T& c, const T& s, const Pose2<T>& b) {
  const T dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, b.theta - a.theta};
}

// a^-1 b: pose b in the frame of pose a, its heading relative to a's (not wrapped). On double and
// on ceres::Jet, as Pose2.
template <typename T>
Pose2<T> Between(const Pose2<T>& a, const Pose2<T>& b) {
  using std::cos;
  using std::sin;
  const T c = cos(a.theta), s = sin(a.theta);
  return BetweenRotated(a, c, s, b);
}

}  // namespace fitcal
