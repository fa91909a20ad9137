#pragma once
// What a fit on the training runs' tracks needs before it starts: --residuals auto resolved and
// the tracks built (or the refusal of a method that fits final poses only), the tracks the effect
// fit replays, and the residual degrees of freedom the fit will have.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "calibrate/fit_methods.h"
#include "fit/effect_fit.h"
#include "fit/run_split.h"

namespace fitcal {

// The training runs' tracks for --residuals track/both, and auto resolved (settings->track points
// into *data): "" when done, else why `method` cannot fit them (the caller refuses, exit 2).
std::string PrepareTrackResiduals(const std::string& method,
                                  const std::vector<AlignedRun>& training,
                                  FitMethodSettings* settings, std::optional<TrackFitData>* data);

// The fit's residual degrees of freedom (validation/residual_dof.h), counted for the residuals
// it will minimise: three final-pose residuals per training run, three per track checkpoint
// (plus the final poses with `both`), and the clock offsets as parameters when estimated. A
// single long free run thus calibrates on its track, where its final pose alone could not.
// "" or the refusal.
std::string DegreesOfFreedomRefusal(const RunSplit& split, const FitMethodSettings& settings,
                                    const std::optional<TrackFitData>& track,
                                    std::size_t num_parameters);

// The training runs prepared for the effect fit's track residuals (`logs` holds every run by id);
// nullopt with *refusal set when some training run has no ground truth between its ends.
std::optional<std::vector<TrackRun>> TrainingTracks(const std::string& dataset, const Robot& robot,
                                                    const std::vector<RunLog>& logs,
                                                    const RunSplit& split, std::string* refusal);

// The parameters the fit moves, under --tie/--hold when given.
std::size_t NumFreeWithTying(const RobotModelInterface& model, const ParameterTying& tying);

}  // namespace fitcal
