#pragma once
// NLopt methods for any robot model on the seam (models/model_interface.h): the search of
// fit/nlopt_search.h over the model's final-pose residuals (Palacin Eq. 14 per run,
// models/pose_errors.h) - the value from the model's double replay (as fit/final_pose_errors.h
// evaluates the CF; for kinematics linear in their channels, from the final-pose kernel of
// odometry/linear_final_pose_kernel.h, equal to rounding), the gradient from the model's
// FinalPoseCost (the residual the Ceres fit minimises). The box is the robot's bounds (normalised
// to [0, 1] per free parameter); held (gauge) parameters stay at their nominal values; the start
// is the nominal (Palacin Eq. 15).

#include <vector>

#include "fit/nlopt_search.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

// Throws std::invalid_argument for invalid options or no runs.
NloptSearchResult FitModelNlopt(const std::vector<AlignedRun>& training,
                                const RobotModelInterface& model,
                                const NloptFitOptions& options = {});

}  // namespace fitcal
