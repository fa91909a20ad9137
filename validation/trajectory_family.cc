#include "validation/trajectory_family.h"

#include <cctype>

namespace fitcal {

std::string TrajectoryFamily(const std::string& label) {
  std::size_t end = 0;
  while (end < label.size() && std::isalpha(static_cast<unsigned char>(label[end]))) ++end;
  if (end > 0) return label.substr(0, end);
  return label.empty() ? "-" : label;
}

}  // namespace fitcal
