#include "calibrate/mount_freed.h"

#include <iomanip>
#include <sstream>

namespace fitcal {

std::string MountFreedLine(const MountedModel& held_model, const std::vector<double>& written,
                           const std::vector<double>& held, double held_cf, double free_cf) {
  const int x = held_model.MountIndex();
  std::ostringstream line;
  line << std::setprecision(4) << "ground_truth_frame: x and y fitted (x " << written[x] << " m, y "
       << written[x + 1] << " m), not held at the guess (x " << held[x] << " m, y " << held[x + 1]
       << " m): held, the wheel distances could not take up its error within their "
       << "bounds (training CF " << held_cf << " held, " << free_cf << " fitted); the runs tell "
       << "the mount from the distances only through those bounds, so measure the mount to check "
       << "the fitted one";
  return line.str();
}

}  // namespace fitcal
