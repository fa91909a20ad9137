#pragma once
// What omni3 offers beyond the seam (models/model_extras.h): omni_wheel_drive_controller
// parameters, its parameters shown as Palacin's M^-1 (Eq. 6) in `compare`, and Palacin's flower as
// its simulation scenario (Table A1's 36 trajectories, driven by APR-02 under the stepped physics
// with Table 5 as the truth: data/flower's bytes come from there).

#include <vector>

#include "models/model_extras.h"
#include "models/omni3/omni3_parameters.h"

namespace fitcal {

ModelExtras Omni3Extras();

// Namespace sim as the flower's trajectories (models/omni/flower_trajectories.h).
namespace sim {
// Palacin Table 5: the STE-GA5 calibrated parameters of APR-02, the flower's default truth.
omni3::Parameters PalacinTable5Parameters();
// The nine parameters in the seam's order (Eq. 15: R_i, r_i, delta_i).
std::vector<double> ParameterVector(const omni3::Parameters& p);
}  // namespace sim

}  // namespace fitcal
