#pragma once
// The 36 flower trajectories (Palacin Table A1) as candidate motions for the identifiability
// advice (diagnosis/identifiability.h): "which trajectories would fix it" is answered from these.

#include <cmath>
#include <vector>

#include "diagnosis/identifiability.h"
#include "tools/sim/flower_trajectories.h"

namespace fitcal::sim {

inline std::vector<CandidateMotion> FlowerCandidateMotions() {
  std::vector<CandidateMotion> out;
  for (const MotionCommand& c : FlowerTrajectories()) {
    CandidateMotion m;
    m.label = c.label;
    m.kind = c.omega_rad_s == 0.0  ? "straight"
             : c.omega_rad_s > 0.0 ? "counter-clockwise curve"
                                   : "clockwise curve";
    m.vx_m_s = c.speed_m_s * std::cos(c.alpha_rad);
    m.vy_m_s = c.speed_m_s * std::sin(c.alpha_rad);
    m.omega_rad_s = c.omega_rad_s;
    m.duration_s = c.distance_m / c.speed_m_s;
    out.push_back(m);
  }
  return out;
}

}  // namespace fitcal::sim
