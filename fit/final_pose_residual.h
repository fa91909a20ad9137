#pragma once
// Transitional: the omni3 final-pose residual that lived here is gone (every model's is
// models/pose_errors.h FinalPoseError, served by RobotModelInterface::FinalPoseCost). Kept only
// for the includes of diagnosis/channel_order_check.h; delete with them.

#include "models/model_interface.h"
