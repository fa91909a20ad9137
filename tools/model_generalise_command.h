#pragma once
// `fitcal generalise` for every robot model on the seam except omni3 (whose table, with its
// segment cost, reduced model and effects, stays in generalisation_command.cc): the splits and
// candidates of validation/generalisation.h, printed as the Markdown tables of the README.

#include "io/dataset.h"
#include "models/model_interface.h"
#include "tools/generalisation_command.h"

namespace fitcal::tools {

int RunModelGeneraliseCommand(const GeneraliseCommandOptions& options,
                              const io::DatasetIndex& index, const RobotModelPtr& model);

}  // namespace fitcal::tools
