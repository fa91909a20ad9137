#pragma once
// The uncertainty of any calibration point, not only of the least-squares fit that found it: a
// closed form (UMBmark, ASOC's geometry, models/*/ClosedForms) or a fit without its holds has no
// covariance of its own, and a written calibration never carries sigma: null. Propagated through
// the final-pose residuals (Palacin Eq. 14) at the point p:
//   J = d r / d p  (3 rows per run, the model's autodiff FinalPoseCost),
//   s^2 = |r(p)|^2 / (m - k)  (m residuals, k free parameters),
//   Cov(p) = s^2 (J^T J)^-1  over the free parameters, zero rows/columns for the held ones.
// At the least-squares minimum this is the fit's own Gauss-Newton covariance; elsewhere (a closed
// form's point) it is the spread the same residuals would allow around it, the linearised answer
// to "how well do these runs pin the parameters down" - said so where it is printed.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

struct PropagatedUncertainty {
  bool ok = false;
  std::string message;        // why not, when !ok
  std::vector<double> sigma;  // per parameter (0 for held ones)
  Eigen::MatrixXd covariance;
};

// `held` per parameter (empty: none held beyond the robot's gauge holds).
PropagatedUncertainty PropagateFinalPoseUncertainty(const RobotModelInterface& model,
                                                    const std::vector<double>& p,
                                                    const std::vector<AlignedRun>& runs,
                                                    const std::vector<bool>& held = {});

}  // namespace fitcal
