#pragma once
// What the parameter table and the calibration record say of the selected candidate: the
// uncertainty, bound contacts and holds of the fit that made it, and the uncertainty propagated
// through the training runs for a candidate without one of its own.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calibrate/candidates.h"

namespace fitcal {

// The uncertainty, bound contacts and holds of the fit that made the selected candidate (none for
// the nominal or a closed form; a fit's bound contacts also for the fit without its holds).
struct SelectedFit {
  bool has_covariance = false;
  std::vector<double> sigma;
  Eigen::MatrixXd correlation;
  std::vector<bool> at_bound, held;  // per parameter
  std::string objective, termination;
  // The weights' noise levels when the fit estimated them (fit/noise_levels.h); else not estimated.
  NoiseLevels noise_levels;
  // Per parameter: not determined by the training runs, its sigma the bounds' along a held
  // direction (NotDeterminedParameters, fit/model_fit.h) or wider than the bounds allow
  // (MarkWiderThanTheBounds).
  std::vector<bool> not_determined;
  // Why parameters beyond the robot's own holds are held when no fit chose them ("" for a fit).
  std::string held_reason;
  // What the sigmas hold beyond the fit's own covariance, one line each (the angle channels'
  // resolution: calibrate/reading_resolution_uncertainty.h).
  std::vector<std::string> sigma_notes;
};

// candidates[selected_index] described by the fit that made it: `fit` (the method's, minimising
// `method_objective`) or one of the track fits.
SelectedFit DescribeSelected(const Robot& robot,
                             const std::vector<CalibrationCandidate>& candidates,
                             int selected_index, const std::string& method,
                             const std::string& method_objective, const ModelFitResult& fit,
                             const std::optional<TrackFits>& track_fits);

// A selected candidate without a covariance of its own (a closed form, a fit without its holds)
// gets the one propagated through the training runs' final-pose residuals at its point
// (validation/propagated_uncertainty.h), with a closed form's own sigmas where it has them: a
// written calibration never has sigma: null. "" when done; else why even that is not possible
// (nothing may then be written).
std::string AddPropagatedUncertainty(const RobotModelInterface& model,
                                     const CalibrationCandidate& selected,
                                     const std::vector<AlignedRun>& training, SelectedFit* fit);

// Marks NOT DETERMINED every parameter whose sigma is wider than its bounds read as a uniform
// prior (width / sqrt(12), PriorSigma in fit/determined_directions.h), whichever fit made it: the
// bounds say more about it than the runs do. A held direction marks its parameters already
// (NotDeterminedParameters); this catches a direction left free, as by a fit without its holds
// whose sigma was propagated (the real omni3's mount yaw and wheel angles on its circles alone,
// sigma 2.3e3 deg within bounds of +-90 deg, said "determined").
void MarkWiderThanTheBounds(const Robot& robot, SelectedFit* fit);

}  // namespace fitcal
