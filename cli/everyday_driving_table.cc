#include "cli/everyday_driving_table.h"

#include <cstdio>

#include "validation/everyday_driving.h"
#include "validation/never_worse.h"

namespace fitcal::tools {

void PrintEverydayDrivingTable(const RobotModelInterface& model,
                               const std::vector<AlignedRun>& runs,
                               const std::vector<const GroundTruthTrack*>& tracks,
                               const std::string& title, const EverydayDrivingColumn& nominal,
                               const EverydayDrivingColumn& calibrated, int threads,
                               bool judge) {
  const std::vector<double> lengths = EverydayDriftLengths();
  const EverydayDrivingMetrics before = EvaluateEverydayDriving(
      model, *nominal.parameters, *nominal.effects, runs, tracks, lengths, threads);
  const EverydayDrivingMetrics after = EvaluateEverydayDriving(
      model, *calibrated.parameters, *calibrated.effects, runs, tracks, lengths, threads);
  // A row that rose says whether the runs' scatter explains it (issue 42: +13 % went unmarked).
  const std::vector<NeverWorseJudgement> judged = JudgeNeverWorse(runs, before, after);
  std::printf("\n  %-30s %10s %10s %9s\n", title.c_str(), "nominal", "calibrated", "change");
  for (const std::string& row : EverydayDrivingRows(before, after, NeverWorseRowNotes(judged)))
    std::printf("%s\n", row.c_str());
  if (!judge) return;
  const std::vector<std::string> worse = NeverWorseRefusals("the calibration", judged);
  if (worse.empty()) {
    std::printf("  never worse than the nominal beyond the runs' scatter (docs/never_worse.md)\n");
  }
  for (const std::string& line : worse) std::printf("  refused as fit would: %s\n", line.c_str());
  for (const std::string& line : NeverWorseRefusals("the calibration", judged, false)) {
    std::printf("  warning: %s\n", line.c_str());
  }
  for (const std::string& line : NeverWorseWithinScatter("the calibration", judged)) {
    std::printf("  warning: %s\n", line.c_str());
  }
}

}  // namespace fitcal::tools
