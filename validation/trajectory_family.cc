#include "validation/trajectory_family.h"

#include <cctype>

namespace fitcal {

std::string TrajectoryFamily(const std::string& label) {
  std::size_t end = 0;
  while (end < label.size() && std::isalpha(static_cast<unsigned char>(label[end]))) ++end;
  if (end > 0) return label.substr(0, end);
  return label.empty() ? "-" : label;
}

std::map<std::string, std::vector<AlignedRun>> RunsByFamily(const std::vector<AlignedRun>& runs) {
  std::map<std::string, std::vector<AlignedRun>> by;
  for (const AlignedRun& run : runs) by[TrajectoryFamily(run.trajectory)].push_back(run);
  return by;
}

}  // namespace fitcal
