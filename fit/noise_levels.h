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
//
// Per session where sessions differ (a session is a run's trajectory label, as the clock offsets'
// `--clock-offsets session` groups runs: ClockGroupOf). Each session s gets the same estimate
// from its own residuals, sigma_{c,s}^2 = S_{c,s} / (n_{c,s} (1 - n_par / n)). Per component,
// Bartlett's test (Snedecor & Cochran, Statistical Methods, 8th ed., Sec. 13.10) asks whether the
// sessions share one level:
//   T = [N ln v_p - sum_s nu_s ln v_s] / [1 + (sum_s 1/nu_s - 1/N) / (3 (k - 1))] ~ chi2(k - 1),
// v_s the session's variance, nu_s its degrees of freedom, N = sum nu_s, v_p = sum nu_s v_s / N.
// nu_s counts checkpoints: dimension x Kish's effective number of a run-weighted mean,
// R_s^2 / sum_r 1/K_r (= sum K_r when the runs' K are equal), times the redundancy. That takes the
// checkpoints as independent, which white ground-truth noise makes them; on real runs the odometry
// drift correlates them and the test finds differences more readily. When T rejects at
// kSessionAlpha / (number of components) (Bonferroni over the components), the session farthest
// from the pool (largest nu_s (ln v_s - ln v_p)^2) leaves it with its own level, and the rest are
// tested again, until they pass. The sessions that stay share the level of their pooled residuals;
// when none leaves, that is the data set's level, to the bit. A session with fewer than
// kMinSessionDegrees degrees of freedom is not tested and takes the pool's level.

#include <array>
#include <string>
#include <vector>

#include "fit/track_residual.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

// The residual components, in NoiseLevels' and SessionNoise's order.
enum NoiseComponent { kTrackPosition, kTrackHeading, kFinalPosition, kFinalHeading };
constexpr int kNumNoiseComponents = 4;

// Family-wise level of the session tests, and the fewest degrees of freedom a session is tested
// with: its sigma then has a relative standard error of at most 1/sqrt(2 * 20) = 16 %, so a level
// 3x another's (9x the variance) stands out while one 20 % off does not split a session alone.
constexpr double kSessionAlpha = 0.01;
constexpr double kMinSessionDegrees = 20.0;

// Each session's level per component (header); a session that does not differ has the pool's.
struct SessionNoise {
  std::vector<std::string> names;  // in the order of their first training run
  std::vector<int> of_run;         // each training run's session
  std::array<std::vector<double>, kNumNoiseComponents> sigma;    // [component][session]
  std::array<std::vector<double>, kNumNoiseComponents> split_p;  // Bartlett p; < 0: pooled
  bool Differs(int component) const;
  bool AnyDiffers() const;
};

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
  SessionNoise sessions;  // per_session only
};

// Relative change of the weights' ratios below which the estimates have settled.
constexpr double kNoiseLevelTolerance = 0.01;
constexpr int kMaxNoiseLevelIterations = 6;

// The components' sigmas at parameters p and clock offsets (one per track.clock_groups), from the
// training runs' tracks and, with `final_poses`, their final poses. num_estimated: free model
// parameters plus estimated clock offsets. Not `estimated` when no degree of freedom is left or a
// replay fails. per_session: also each session's levels where sessions differ (header).
NoiseLevels EstimateNoiseLevels(const std::vector<AlignedRun>& training,
                                const RobotModelInterface& model, const std::vector<double>& p,
                                const std::vector<double>& clock_offsets_s,
                                const TrackFitData& track, bool final_poses, int num_estimated,
                                bool per_session = true);

// The weights for the track residuals and, with final poses, for them (scale-free: relative to the
// track's position sigma, header).
struct FitWeights {
  ResidualWeights track;
  ResidualWeights final_pose;
};
FitWeights WeightsFromNoiseLevels(const NoiseLevels& levels);
// One per training run, from its session's levels (relative to the data set's track position
// sigma, as above); empty when no session differs.
std::vector<FitWeights> WeightsPerRun(const NoiseLevels& levels);

// Whether the ratios of `a` and `b` agree within kNoiseLevelTolerance.
bool NoiseLevelsAgree(const NoiseLevels& a, const NoiseLevels& b);

// One line for the terminal and the calibration's objective, e.g. "track position 0.0123 m,
// heading 0.712 deg per checkpoint (3 fits, settled)"; where sessions differ, each component's
// levels by session, e.g. "track position 0.012 m (sessions A, B), 0.031 m (session C: differs,
// Bartlett p = 2e-06)", the components joined by `separator`.
std::string NoiseLevelsText(const NoiseLevels& levels, const std::string& separator = "; ");

}  // namespace fitcal
