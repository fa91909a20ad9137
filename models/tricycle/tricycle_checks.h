#pragma once
// Checks of a tricycle's steering channel that a loader runs before anything is fitted or
// written: a steering angle outside [-pi, pi], a steering column that is plainly encoder ticks
// rather than radians (whole numbers beyond 2 pi), a log without the steering channel. Each
// throws io::InputError naming the file and the line of the first offending row (one line for
// the user, nothing written).

#include <cstddef>
#include <string>
#include <vector>

#include "odometry/run_log.h"

namespace fitcal::tricycle {

// The steering readings of one encoder CSV column, in row order; the reading of row k sits on
// line first_line + k of `path` (2 for a CSV with one header line). Ticks are diagnosed before
// the range so that the message names the cause.
void CheckSteeringReadings(const std::vector<double>& readings_rad, const std::string& path,
                           int first_line = 2);

// The same on an encoder log as the replay sees it (2 channels: traction rate, steering angle
// per interval); an interval's steering value is the mean of two readings, so it lies inside
// [-pi, pi] whenever they do. Sample k covers rows k and k + 1 of the CSV (lines k + 2, k + 3).
void CheckSteeringSamples(const EncoderLog& log, const std::string& path);

}  // namespace fitcal::tricycle
