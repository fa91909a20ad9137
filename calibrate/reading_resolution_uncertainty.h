#pragma once
// A sigma floor from the angle channels' resolution (odometry/reading_resolution.h). While the
// robot holds an angle, its reading stays on one count, and the count's error - a constant in
// [-q/2, q/2], uniform: sigma q / sqrt(12), less where noise dithers the readings
// (ReadingResolution::BiasSigma) - biases the parameters in a way no number of runs averages
// away; a covariance of the noise alone does not hold it (docs/everyday_driving.md, "Sigmas that
// cover": a 12-bit steering encoder left the fitted offset beyond 3 sigma). Its part of the
// parameters' covariance is found by refitting: the training runs' channel shifted by that sigma,
// the fit warm-started from the selected calibration, dp its move; the covariance gains dp dp^T
// per quantised channel (one constant error over every run: conservative where the angle sweeps
// through many counts, whose errors partly cancel).

#include <string>
#include <vector>

#include "calibrate/fit_methods.h"
#include "calibrate/selected_fit.h"
#include "odometry/aligned_run.h"
#include "odometry/run_log.h"

namespace fitcal {

// Per channel of `robot`: the largest reading step over the runs, and the flicker of the runs that
// show one pooled (EncoderLog::reading_resolution).
std::vector<ReadingResolution> ReadingResolutionsOf(const Robot& robot,
                                                    const std::vector<RunLog>& runs);

// Adds each quantised channel's part to `fit`'s covariance (sigma and correlation), for the
// method's own fit at `parameters`, and one line per channel to its sigma_notes ("channel
// 'steering' reads in steps of 0.45 deg: ..."). Nothing when no channel is quantised or the fit
// has no covariance; NLopt methods, which search their box and take no start, say so and add
// nothing.
void AddReadingResolutionUncertainty(
    const FitMethod& method, const FitMethodSettings& settings, const RobotModelInterface& model,
    const std::vector<AlignedRun>& training, const std::vector<ReadingResolution>& resolutions,
    const std::vector<double>& parameters, SelectedFit* fit);

}  // namespace fitcal
