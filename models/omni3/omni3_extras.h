#pragma once
// What omni3 offers beyond the seam (models/model_extras.h): omni_wheel_drive_controller
// parameters, its parameters shown as Palacin's M^-1 (Eq. 6) in `compare`, and the two older
// paths it still takes: the stepped flower simulator (data/flower's bytes) and compare's
// three-wheel loader with Palacin's strategies.

#include "models/model_extras.h"

namespace fitcal {

ModelExtras Omni3Extras();

}  // namespace fitcal
