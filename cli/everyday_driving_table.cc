#include "cli/everyday_driving_table.h"

#include <cstdio>

namespace fitcal::tools {

void PrintEverydayDrivingTable(const std::string& title, const EverydayDrivingComparison& table,
                               bool judge) {
  std::printf("\n  %-30s %10s %10s %9s\n", title.c_str(), "nominal", "calibrated", "change");
  for (const std::string& row : table.rows) std::printf("%s\n", row.c_str());
  if (!judge) return;
  const NeverWorseSaid said = SayNeverWorse("the calibration", table.judgements);
  if (said.refusals.empty()) {
    std::printf("  never worse than the nominal beyond the runs' scatter (docs/never_worse.md)\n");
  }
  for (const std::string& line : said.refusals) {
    std::printf("  refused as fit would: %s\n", line.c_str());
  }
  for (const std::string& line : said.warnings) std::printf("  warning: %s\n", line.c_str());
}

}  // namespace fitcal::tools
