#include "models/tricycle/tricycle_trajectories.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "odometry/text_format.h"

namespace fitcal::sim {

namespace {

// One circle at steering angle phi' (T2): omega = v tan(phi') / L, the heading turns by
// 2 pi turns in 2 pi turns / |omega|.
TwistSegment Circle(const TricycleTrajectoryOptions& o, double steering_rad) {
  const double omega = o.speed_m_s * std::tan(steering_rad) / o.wheelbase_m;
  return {Twist{o.speed_m_s, 0.0, omega}, 2.0 * M_PI * kCircleTurns / std::abs(omega)};
}

// A quarter turn (sign +1 = ccw): in place, or an arc at the largest steering the robot reads,
// or less where that arc would be over in under min_corner_s (a steering gain of 0.52-0.55 reads
// at most 86-88 deg: a quarter turn of 0.08 s, and `simulate` exited 1; found by a randomized
// sweep, stop 65).
TwistSegment Corner(const TricycleTrajectoryOptions& o, double sign) {
  if (o.max_steering_deg >= 90.0) {
    return {Twist{0.0, 0.0, sign * o.turn_rate_rad_s}, 0.5 * M_PI / o.turn_rate_rad_s};
  }
  TwistSegment arc = Circle(o, sign * o.max_steering_deg * M_PI / 180.0);
  arc.duration_s = 0.5 * M_PI / std::abs(arc.twist.omega_rad_s);
  if (arc.duration_s < o.min_corner_s) {
    arc.duration_s = o.min_corner_s;
    arc.twist.omega_rad_s = sign * 0.5 * M_PI / o.min_corner_s;
  }
  return arc;
}

// Four straight sides, each followed by a quarter turn (sign +1 = ccw), and the first side again.
std::vector<TwistSegment> Square(const TricycleTrajectoryOptions& o, double sign) {
  const TwistSegment side{Twist{o.speed_m_s, 0.0, 0.0}, o.square_side_m / o.speed_m_s};
  const TwistSegment corner = Corner(o, sign);
  std::vector<TwistSegment> out;
  for (int i = 0; i < 4; ++i) {
    out.push_back(side);
    out.push_back(corner);
  }
  out.push_back(side);  // open: ends a side away from the start (header)
  return out;
}

}  // namespace

std::string TricycleTrajectoryOptions::Check() const {
  if (!(wheelbase_m > 0.0)) return "wheelbase_m must be positive";
  if (!(speed_m_s > 0.0)) return "speed_m_s must be positive";
  if (!(square_side_m > 0.0)) return "square_side_m must be positive";
  if (!(turn_rate_rad_s > 0.0)) return "turn_rate_rad_s must be positive";
  if (!(min_corner_s > 0.0)) return "min_corner_s must be positive";
  if (repetitions < 1) return "repetitions must be at least 1";
  if (!(max_steering_deg > 0.0 && max_steering_deg <= 90.0)) {
    return "max_steering_deg must lie in (0, 90]";
  }
  for (double deg : steering_deg) {
    if (!(deg > 0.0 && deg < 90.0)) return "circle steering angles must lie in (0, 90) deg";
    if (deg > max_steering_deg) return "a circle steers beyond max_steering_deg";
  }
  return "";
}

std::vector<TrajectorySpec> TricycleTrajectories(const TricycleTrajectoryOptions& options) {
  const std::string error = options.Check();
  if (!error.empty()) throw std::invalid_argument("tricycle trajectories: " + error);
  std::vector<TrajectorySpec> shapes;
  for (double deg : options.steering_deg) {
    for (double sign : {1.0, -1.0}) {
      shapes.push_back({StrFormat("circle_%s_%g", sign > 0.0 ? "ccw" : "cw", deg), 1,
                        {Circle(options, sign * deg * M_PI / 180.0)}});
    }
  }
  shapes.push_back({"square_ccw", 1, Square(options, 1.0)});
  shapes.push_back({"square_cw", 1, Square(options, -1.0)});
  std::vector<TrajectorySpec> out;
  for (int rep = 1; rep <= options.repetitions; ++rep) {
    for (TrajectorySpec spec : shapes) {
      spec.repetition = rep;
      out.push_back(std::move(spec));
    }
  }
  return out;
}

double TricycleReadableSteeringDeg(double steering_gain, double steering_offset_rad) {
  constexpr double kReadableColumnDeg = 160.0;  // 180 less a margin for the reading's noise
  const double readable =
      std::abs(steering_gain) * kReadableColumnDeg - std::abs(steering_offset_rad) * 180.0 / M_PI;
  return std::min(90.0, readable);
}

}  // namespace fitcal::sim
