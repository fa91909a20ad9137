#include "tools/sim/omni_trajectories.h"

#include <cmath>
#include <string>

namespace fitcal::sim {

namespace {

// The flower's families: straight, counter-clockwise and clockwise (Table A1's R, G, B).
constexpr struct {
  char label;
  double omega_sign;
} kFamilies[] = {{'R', 0.0}, {'G', 1.0}, {'B', -1.0}};

TrajectorySpec Spin(bool clockwise, int repetition, const OmniTrajectoryOptions& options) {
  TrajectorySpec spec;
  spec.label = clockwise ? "S-cw" : "S-ccw";
  spec.repetition = repetition;
  const double omega = (clockwise ? -1.0 : 1.0) * options.spin_rate_rad_s;
  spec.segments.push_back({{0.0, 0.0, omega}, options.spin_angle_rad / options.spin_rate_rad_s});
  return spec;
}

}  // namespace

std::vector<TrajectorySpec> OmniFlowerTrajectories(int repetitions,
                                                   const OmniTrajectoryOptions& options) {
  std::vector<TrajectorySpec> out;
  const double duration_s = options.distance_m / options.speed_m_s;
  for (int rep = 1; rep <= repetitions; ++rep) {
    for (const auto& family : kFamilies) {
      for (int i = 1; i <= options.num_directions; ++i) {
        const double alpha_rad = 2.0 * M_PI * (i - 1) / options.num_directions;
        TrajectorySpec spec;
        spec.label = std::string(1, family.label) + std::to_string(i);
        spec.repetition = rep;
        const Twist twist{options.speed_m_s * std::cos(alpha_rad),
                          options.speed_m_s * std::sin(alpha_rad),
                          family.omega_sign * options.omega_abs_rad_s};
        spec.segments.push_back({twist, duration_s});
        out.push_back(spec);
      }
    }
    if (options.spin_angle_rad > 0.0) {
      out.push_back(Spin(false, rep, options));
      out.push_back(Spin(true, rep, options));
    }
  }
  return out;
}

}  // namespace fitcal::sim
