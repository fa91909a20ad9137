// The omni model of 4 wheels in its own translation unit (omni_model_n.h says why).
#include "models/omni/omni_model_n.h"

namespace fitcal {
template RobotModelPtr BuildOmniModel<4>(Robot, const std::vector<OmniWheel>&, const OmniBounds&);
template bool FillOmniWheelMounts<4>(const RobotModelInterface&, std::vector<OmniWheel>*);
}  // namespace fitcal
