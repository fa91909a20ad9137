#include "calibrate/checks_before_fitting.h"

#include "diagnosis/channel_order_check.h"
#include "diagnosis/degenerate_data.h"
#include "validation/rate_units.h"

namespace fitcal {

namespace {

// The refusal's reason when another channel order explains the runs far better; else "".
std::string MiswiredChannels(const CalibrationRequest& request, const RobotModelInterface& model,
                             const std::vector<AlignedRun>& training) {
  ChannelOrderOptions order_options;
  order_options.weights.position_sigma_m = request.position_sigma_m;
  order_options.weights.heading_sigma_rad = DegToRad(request.heading_sigma_deg);
  order_options.num_threads = request.threads;
  const ChannelOrderReport order =
      CheckRecordedChannelOrder(training, TracksOf(training), model, order_options);
  if (!order.likely_miswired) return "";
  return request.dataset + ": " + order.message +
         "; nothing written (--skip-wheel-order-check to fit anyway)";
}

}  // namespace

std::string StillTrainingRunsRefusal(const std::string& dataset, const std::vector<RunLog>& runs,
                                     const std::vector<std::string>& training_ids,
                                     const Robot& robot) {
  // The logs themselves, not copies: a copy of every training run's samples cost a tenth of the
  // checks (a 97-run data set).
  std::vector<const RunLog*> training_logs;
  for (const std::string& id : training_ids) {
    for (const RunLog& log : runs) {
      if (log.id == id) training_logs.push_back(&log);
    }
  }
  const std::string still = StillRunsRefusal(training_logs, robot);
  return still.empty() ? still : dataset + ": " + still;
}

int CheckBeforeFitting(const CalibrationRequest& request, const RobotModelInterface& model,
                       const RunSplit& split, std::vector<std::string>* warnings,
                       std::string* reason) {
  std::vector<std::string> training_ids;
  for (const AlignedRun& run : split.training) training_ids.push_back(run.id);
  if (std::string still =
          StillTrainingRunsRefusal(request.dataset, request.runs, training_ids, model.robot());
      !still.empty()) {
    *reason = std::move(still);
    return 1;
  }
  if (const RateUnitsFinding units = CheckModelRateUnits(model, request.runs); units.suspicious) {
    *reason = request.dataset + ": " + units.message;
    return 1;
  }
  if (request.check_channel_order) {
    *reason = MiswiredChannels(request, model, split.training);
    if (!reason->empty()) return 4;
  }
  for (const std::string& problem : FindDegenerateData(split.training, model.robot())) {
    warnings->push_back(problem);
  }
  return 0;
}

}  // namespace fitcal
