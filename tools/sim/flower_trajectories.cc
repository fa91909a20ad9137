#include "tools/sim/flower_trajectories.h"

#include <cmath>

namespace fitcal::sim {

std::vector<MotionCommand> FlowerTrajectories(double speed_m_s, double omega_abs_rad_s,
                                              double distance_m) {
  std::vector<MotionCommand> out;
  const struct {
    char family;
    double omega_sign;
  } families[] = {{'R', 0.0}, {'G', 1.0}, {'B', -1.0}};
  for (const auto& family : families) {
    for (int i = 1; i <= 12; ++i) {
      MotionCommand c;
      c.label = std::string(1, family.family) + std::to_string(i);
      c.speed_m_s = speed_m_s;
      c.alpha_rad = (i - 1) * 30.0 * M_PI / 180.0;
      c.omega_rad_s = family.omega_sign * omega_abs_rad_s;
      c.distance_m = distance_m;
      out.push_back(c);
    }
  }
  return out;
}

}  // namespace fitcal::sim
