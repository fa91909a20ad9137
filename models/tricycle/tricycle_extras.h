#pragma once
// What the tricycle offers beyond the seam (models/model_extras.h): tricycle_controller parameters
// and the circles-and-squares simulation scenario.

#include "models/model_extras.h"

namespace fitcal {

ModelExtras TricycleExtras();

}  // namespace fitcal
