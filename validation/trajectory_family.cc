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

std::vector<std::string> UnjudgedFamilyNotes(const std::vector<AlignedRun>& training,
                                             const std::vector<AlignedRun>& validation) {
  std::vector<std::string> notes;
  if (validation.empty()) return notes;
  const auto held_out = RunsByFamily(validation);
  for (const auto& [family, runs] : RunsByFamily(training)) {
    if (held_out.count(family) > 0) continue;
    notes.push_back("note: all " + std::to_string(runs.size()) + " run(s) of '" + family +
                    "' train and none is held out, so no '" + family +
                    "' run judges the calibration; to judge on them, import them as a data set "
                    "of their own and run fitcal report on it (README, worked example), or hold "
                    "them out with --train-trajectories");
  }
  return notes;
}

}  // namespace fitcal
