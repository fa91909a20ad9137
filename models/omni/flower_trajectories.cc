#include "models/omni/flower_trajectories.h"

#include <cmath>
#include <stdexcept>

namespace fitcal::sim {

std::vector<MotionCommand> FlowerTrajectories(double speed_m_s, double omega_abs_rad_s,
                                              double distance_m, int num_directions) {
  std::vector<MotionCommand> out;
  const struct {
    char family;
    double omega_sign;
  } families[] = {{'R', 0.0}, {'G', 1.0}, {'B', -1.0}};
  for (const auto& family : families) {
    for (int i = 1; i <= num_directions; ++i) {
      MotionCommand c;
      c.label = std::string(1, family.family) + std::to_string(i);
      c.speed_m_s = speed_m_s;
      // In degrees first: with n = 12 the bits of Table A1's 30 (i - 1) deg (the shipped flower).
      c.alpha_rad = (i - 1) * (360.0 / num_directions) * M_PI / 180.0;
      c.omega_rad_s = family.omega_sign * omega_abs_rad_s;
      c.distance_m = distance_m;
      out.push_back(c);
    }
  }
  return out;
}

std::vector<TrajectorySpec> FlowerSpecs(const std::vector<MotionCommand>& commands,
                                        int repetitions) {
  if (repetitions < 1) throw std::invalid_argument("simulation: repetitions must be >= 1");
  if (commands.empty()) throw std::invalid_argument("simulation: no trajectories");
  std::vector<TrajectorySpec> out;
  for (int rep = 1; rep <= repetitions; ++rep) {
    for (const MotionCommand& c : commands) {
      if (!(c.speed_m_s > 0.0 && c.distance_m > 0.0)) {
        throw std::invalid_argument("simulation: trajectory needs speed > 0 and distance > 0");
      }
      // Eq. 1 / Table A1: speed v in direction alpha of the robot frame while turning at omega.
      const Twist twist{c.speed_m_s * std::cos(c.alpha_rad), c.speed_m_s * std::sin(c.alpha_rad),
                        c.omega_rad_s};
      out.push_back({c.label, rep, {{twist, c.distance_m / c.speed_m_s}}});
    }
  }
  return out;
}

}  // namespace fitcal::sim
