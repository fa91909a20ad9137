#pragma once
// TUM trajectory files (the format of the TUM RGB-D benchmark, read by evo): one pose per line,
//   timestamp tx ty tz qx qy qz qw
// with time in seconds, position in metres and the orientation as a unit quaternion. A planar
// pose (x, y, theta) is written with tz = 0 and q = (0, 0, sin(theta / 2), cos(theta / 2)).
// `report --tum` writes the ground truth, nominal and calibrated odometry of each judged run, so
// that its drift and ATE figures can be checked with the tools people already use (docs/tum.md).

#include <string>
#include <vector>

#include "odometry/pose2.h"

namespace fitcal::io {

// The text of a TUM file: every number with 17 significant digits, so that a reader
// (io/log_files.h ReadGroundTruth reads TUM too) gets the poses back to rounding.
std::string TumText(const std::vector<double>& t_s, const std::vector<Pose2d>& poses);

// A run id as a file name, one to one (two runs never share a file): the id's bytes, with every
// byte outside [A-Za-z0-9._-] and a leading '.' written as %XX (two upper-case hex digits, as in
// URLs), so '%' itself becomes %25: "loop/1" -> "loop%2F1", "loop_1" -> "loop_1", ".a" -> "%2Ea".
std::string FileNameOf(const std::string& id);

}  // namespace fitcal::io
