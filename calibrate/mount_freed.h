#pragma once
// The check `fit` and `diagnose` make on a sideways robot whose pose source's x and y are held at
// their guess (models/mounted_model.h): the wheel distances take up the guess's error only within
// their bounds, so a fit with x and y free may predict the training runs far better, and then the
// whole calibration is made with it.

#include <string>
#include <vector>

#include "models/mounted_model.h"

namespace fitcal {

// The fit with the mount freed replaces the one with it held when its training CF is below this
// fraction of the held fit's. Where the wheel distances take up the guess's error the two fits
// predict alike (the gauge is exact, models/mounted_model.h: CF equal to the solver's tolerance),
// so a fifth lower is far above that; a guess they cannot take up costs far more (a simulated
// omni3 with the mount 0.29 m off: CF 0.154 held, 0.030 freed).
inline constexpr double kMountFreedCfRatio = 0.8;

// The warning when it did: the fitted and the guessed x and y, and the two training CFs.
std::string MountFreedLine(const MountedModel& held_model, const std::vector<double>& written,
                           const std::vector<double>& held, double held_cf, double free_cf);

}  // namespace fitcal
