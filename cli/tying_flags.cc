#include "cli/tying_flags.h"

#include <cstdio>

#include "io/text_file.h"

namespace fitcal::tools {

void AddTyingFlags(CLI::App& app, TyingFlags& flags) {
  app.add_option("--tie", flags.tie,
                 "Parameters sharing one value, named as the robot's parameters (e.g. "
                 "\"R_a,R_b,R_c\" or \"r_left,r_right\"); repeat for more groups");
  app.add_option("--hold", flags.hold,
                 "Parameters held at their nominal values (e.g. delta_a,delta_b,delta_c)")
      ->delimiter(',');
}

std::string ReadTying(const TyingFlags& flags, const Robot& robot, ParameterTying* tying) {
  *tying = {};
  // "R_a, R_b,R_c" -> {"R_a", "R_b", "R_c"}; empty names are kept, so that CheckTying refuses them.
  for (const std::string& group : flags.tie) tying->groups.push_back(io::SplitCsvFields(group));
  for (const std::string& name : flags.hold) {
    for (const std::string& n : io::SplitCsvFields(name)) tying->held.push_back(n);
  }
  return CheckTying(robot, *tying);
}

void PrintTying(const ParameterTying& tying) {
  for (const std::vector<std::string>& group : tying.groups) {
    std::string names;
    for (const std::string& name : group) names += (names.empty() ? "" : "=") + name;
    std::printf("tied (one value): %s\n", names.c_str());
  }
  if (tying.held.empty()) return;
  std::string names;
  for (const std::string& name : tying.held) names += (names.empty() ? "" : ", ") + name;
  std::printf("held at nominal (--hold): %s\n", names.c_str());
}

}  // namespace fitcal::tools
