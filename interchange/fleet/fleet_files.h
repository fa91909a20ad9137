#pragma once
// What `fitcal fleet` reads: calibrated robot YAMLs and reports' metrics.json, as a fleet's
// nightly jobs write them (deploy/k8s), each dated by the first YYYY-MM-DD in its path, the robot
// the YAML's `name` (or the report's `robot`). Directories are searched recursively for *.yaml
// files that hold a `calibration:` block and for metrics.json. Reads what users hand in, so it
// is instrumented in the sanitizer build as the commands are; the statistics over the series
// are validation/fleet_statistics.h.

#include <string>
#include <vector>

#include "validation/fleet_statistics.h"

namespace fitcal {

// Every calibration found in the inputs, as series per robot and parameter (FleetSeriesOf).
// Throws io::InputError (file:line) on a file it cannot read whole, UsageError when none is found.
std::vector<FleetSeries> ReadFleet(const std::vector<std::string>& inputs);

}  // namespace fitcal
