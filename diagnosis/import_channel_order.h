#pragma once
// The channel-order check every OptiOdom importer runs before it writes: the one check of which
// encoder column is which channel (diagnosis/channel_order_check.h, on the model seam), on the
// runs as imported with the documented order, against the ground truth.

#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/run_log.h"

namespace fitcal {

// The line to print when the documented order stands (its SSR at the nominal and the best other
// order's). Throws MiswiredError (diagnosis/miswired_error.h) with the check's message when another
// order explains the ground truth far better, unless `skip`; with `skip` the line says so.
std::string CheckImportedChannelOrder(const std::vector<RunLog>& logs,
                                      const RobotModelInterface& model, bool skip);

}  // namespace fitcal
