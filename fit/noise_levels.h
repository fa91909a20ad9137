#pragma once
// Weights from the data: the noise level of each kind of residual a track fit mixes, estimated at
// the solution as variance components (Helmert; Foerstner 1979): fit, estimate each component's
// variance from its residuals with its share of the degrees of freedom, reweight, refit
// warm-started, until the estimates settle (fit/model_fit.cc FitModelFrom).
//
// Why: metres and radians are not the same unit. The track residual mixes the position (m) and
// the heading (rad) at every checkpoint, and `--residuals both` adds each run's final pose; 1 m
// against 1 rad (Palacin Eq. 14's CF) is a guess that suits no robot in particular (on the real
// OptiOdom robots the heading's weight decided which calibration transferred,
// docs/everyday_driving.md). Each component c with residuals e_c (SI units, unit weights) gets
//   sigma_c^2 = S_c / (n_c (1 - n_par / n)),
// where S_c is its weighted sum of squares (a track's checkpoints weigh 1/K each, as in the fit:
// every run adds the mean of its checkpoints, fit/track_residual.h), n_c the number of runs times
// the component's dimension (2 for a position, 1 for a heading), n the number of residuals and
// n_par the parameters estimated (free model parameters and clock offsets): the redundancy of
// each component taken as its share of the whole (the simplified Helmert estimate; exact when the
// parameters draw on every component alike).
//
// Only the ratios change the minimum; the common scale is the residual variance the covariance
// is scaled by anyway (fit/ceres_problem.h). The weights the fit uses are therefore the sigmas
// relative to the track's position sigma (WeightsFromNoiseLevels): positions keep 1, so the
// track's Huber scale stays in metres.

#include <string>
#include <vector>

#include "fit/track_residual.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

// Standard deviations per residual component (SI units: m per axis, rad).
struct NoiseLevels {
  bool estimated = false;
  bool with_final_poses = false;  // `both`: the final poses are a component of their own
  double track_position_m = 0.0;  // per checkpoint and axis
  double track_heading_rad = 0.0;
  double final_position_m = 0.0;  // with_final_poses only
  double final_heading_rad = 0.0;
  int iterations = 0;    // fits made (each warm-started from the last)
  bool settled = false;  // the last two estimates agree within kNoiseLevelTolerance
};

// Relative change of the weights' ratios below which the estimates have settled.
constexpr double kNoiseLevelTolerance = 0.01;
constexpr int kMaxNoiseLevelIterations = 6;

// The components' sigmas at parameters p and clock offsets (one per track.clock_groups), from the
// training runs' tracks and, with `final_poses`, their final poses. num_estimated: free model
// parameters plus estimated clock offsets. Not `estimated` when no degree of freedom is left or a
// replay fails.
NoiseLevels EstimateNoiseLevels(const std::vector<AlignedRun>& training,
                                const RobotModelInterface& model, const std::vector<double>& p,
                                const std::vector<double>& clock_offsets_s,
                                const TrackFitData& track, bool final_poses, int num_estimated);

// The weights for the track residuals and, with final poses, for them (scale-free: relative to the
// track's position sigma, header).
struct FitWeights {
  ResidualWeights track;
  ResidualWeights final_pose;
};
FitWeights WeightsFromNoiseLevels(const NoiseLevels& levels);

// Whether the ratios of `a` and `b` agree within kNoiseLevelTolerance.
bool NoiseLevelsAgree(const NoiseLevels& a, const NoiseLevels& b);

// One line for the terminal and the calibration's objective, e.g. "track position 0.0123 m,
// heading 0.712 deg per checkpoint (3 fits, settled)".
std::string NoiseLevelsText(const NoiseLevels& levels);

}  // namespace fitcal
