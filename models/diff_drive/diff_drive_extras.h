#pragma once
// What the differential drive offers beyond the seam (models/model_extras.h): diff_drive_controller
// parameters and the UMBmark-and-circles simulation scenario.

#include "models/model_extras.h"

namespace fitcal {

ModelExtras DiffDriveExtras();

}  // namespace fitcal
