// The omni model of 8 wheels in its own translation unit (omni_model_n.h says why).
#include "models/omni/omni_model_n.h"

namespace fitcal {
template RobotModelPtr BuildOmniModel<8>(Robot, const std::vector<OmniWheel>&, const OmniBounds&);
template bool FillOmniWheelMounts<8>(const RobotModelInterface&, std::vector<OmniWheel>*);
}  // namespace fitcal
