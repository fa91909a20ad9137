#pragma once
// BuildOmniModel<N>: the model of N wheels (3..8) from its description, gauge held (omni_model.h).
// Defined in omni_model_n.h and instantiated once per N in omni_model_<N>.cc (why: there).

#include <vector>

#include "models/model_interface.h"
#include "models/omni/omni_model.h"

namespace fitcal {

// Throws std::invalid_argument when the wheels' kinematic matrix is not of full rank.
template <int N>
RobotModelPtr BuildOmniModel(Robot robot, const std::vector<OmniWheel>& wheels,
                             const OmniBounds& box);

// Each wheel's drive offset and roller angle from an omni model of N wheels into (*wheels)[i];
// false when `model` is not one (OmniWheelsOf, omni_model.h).
template <int N>
bool FillOmniWheelMounts(const RobotModelInterface& model, std::vector<OmniWheel>* wheels);

}  // namespace fitcal
