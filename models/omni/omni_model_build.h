#pragma once
// BuildOmniModel<N>: the model of N wheels (3..8) from its description, gauge held (omni_model.h).
// Defined in omni_model_n.h and instantiated once per N in omni_model_<N>.cc (why: there).

#include <Eigen/Core>
#include <array>
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

namespace omni_model_internal {

// Singular values below this fraction of the largest count as zero: the kinematic matrix's
// (geometry check) and the parameter Jacobian's (gauge). Both are computed in units where every
// entry is O(1), so 1e-9 separates rounding (1e-15) from a real direction by orders of magnitude.
inline constexpr double kRankTolerance = 1e-9;

// The held parameters of an omni robot of `wheels` wheels from g, the 9 x 3N Jacobian of
// vec(F(p) J(p0)) (omni_model_n.h: TwistJacobian); candidates to hold are taken from the last
// wheel backwards in each block starting at candidate_firsts (angles, distances, radii).
std::vector<HeldParameter> GaugeOfTwistJacobian(const Eigen::MatrixXd& g, const Robot& robot,
                                                const std::array<int, 3>& candidate_firsts,
                                                int wheels);

}  // namespace omni_model_internal

}  // namespace fitcal
