#include "diagnosis/import_channel_order.h"

#include "diagnosis/channel_order_check.h"
#include "diagnosis/miswired_error.h"
#include "odometry/aligned_run.h"
#include "odometry/text_format.h"

namespace fitcal {

std::string CheckImportedChannelOrder(const std::vector<RunLog>& logs,
                                      const RobotModelInterface& model, bool skip) {
  const std::vector<AlignedRun> runs = AlignRuns(logs);
  std::vector<const GroundTruthTrack*> tracks;
  for (const RunLog& log : logs) tracks.push_back(&log.ground_truth);
  ChannelOrderOptions options;
  options.score_every_mapping = true;  // the best other order's SSR is printed below
  const ChannelOrderReport report = CheckRecordedChannelOrder(runs, tracks, model, options);
  if (report.likely_miswired && !skip) {
    throw MiswiredError(report.message +
                        "; nothing written (--skip-mapping-check to write anyway)");
  }
  if (report.likely_miswired) return "channel order check: " + report.message + "; written anyway";
  if (report.best.column.empty()) return "channel order check: the model has no other order";
  return StrFormat(
      "channel order check (%zu runs, %s at the nominal): documented order %.4g, best "
      "other (%s) %.4g",
      runs.size(), report.on_windows ? "SSR over 0.5 m windows" : "final-pose SSR",
      report.recorded_nominal_ssr, DescribeChannelMapping(model.robot(), report.best).c_str(),
      report.best_nominal_ssr);
}

}  // namespace fitcal
