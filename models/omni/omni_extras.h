#pragma once
// What the omni robot offers beyond the seam (models/model_extras.h): mecanum_drive_controller and
// omni_wheel_drive_controller parameters, and the flower generalised to its wheels as simulation
// scenario. The omni-wheel writer serves omni3 too (models/omni3/omni3_extras.h).

#include "models/model_extras.h"

namespace fitcal {

// What the export replays for omni_wheel_drive_controller: a model of the controller's equally
// spaced wheels, or the calibrated model with each wheel's R_, r_ and delta_ set to the
// controller's values (a model whose wheels are tangential by construction, omni3).
enum class OmniWheelReplay { kControllerGeometry, kOwnModelByName };

// omni_wheel_drive_controller: one radius, one distance, equally spaced wheels driven
// tangentially.
ControllerWriter OmniWheelController(OmniWheelReplay replay);

ModelExtras OmniExtras();

}  // namespace fitcal
