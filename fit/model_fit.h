#pragma once
// Fits a robot model's parameters to the final poses of a set of runs with Ceres (Palacin
// Sec. 2.6 for omni3, the same for every model): one residual block per run (the model's
// FinalPoseCost, models/pose_errors.h), autodiff through the replay, started from the robot's
// nominal parameters (Palacin Eq. 15) and bounded by its box (Eq. 16). Parameters the model
// holds by construction (Robot::held, gauge) stay at their nominal values.
//
// Bounds by an active set. Ceres' bounded Levenberg-Marquardt projects each step onto the box;
// when the minimum lies outside the box, a parameter rests on its bound and the projected steps
// keep shrinking without meeting Ceres' convergence tests, so the solve ends NO_CONVERGENCE at a
// perfectly good constrained minimum. The fit therefore (1) solves with bounds, ending the solve
// as soon as a free parameter has rested on its bound for three successful steps (the crawl
// starts there; waiting for the iteration limit cost the OptiOdom four-wheel folds 100 iterations
// each); (2) if that did not converge, fixes every parameter resting on a bound at that bound,
// and re-solves the rest, fixing in the same way any parameter that comes to rest on a bound
// during a round; (3) releases a fixed parameter whose gradient points into the box (moving it
// inward would lower the cost: it was not a constrained minimum for it) and repeats, at most
// kMaxActiveSetRounds times. The result is the Karush-Kuhn-Tucker point of the box problem.
//
// Fit what the data determine: see ModelFitOptions::hold_undetermined.
//
// Uncertainty: final poses and segments, the Ceres covariance of the free parameters scaled by
// the residual variance s^2 = |r|^2 / (3 N - n_free) (runs and windows are independent). Tracks
// (and both), the sandwich H^-1 M H^-1 of fit/serial_covariance.h: a run's checkpoint errors are
// a random walk, not independent. Parameters at a bound are flagged; their sigma then describes
// the unconstrained problem only. Directions held because the runs do not determine them
// (hold_undetermined) add what the bounds say about the nominal along them (the box as a
// uniform prior, fit/determined_directions.h): a parameter that moves along a held direction is
// written with the sigma of what the user knew, not the near-zero sigma of the stiff hold.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "fit/determined_directions.h"
#include "fit/noise_levels.h"
#include "fit/parameter_tying.h"
#include "fit/solver_options.h"
#include "fit/track_residual.h"
#include "models/model_interface.h"
#include "odometry/aligned_run.h"

namespace fitcal {

struct ModelFitResult {
  bool usable = false;  // converged to finite parameters; check before using them
  // Stopped at the iteration limit (NO_CONVERGENCE) with finite parameters: a point that may
  // still be good; commands let it compete in the result gate and flag it when it wins.
  bool stopped_early = false;
  // Parameters a gate may judge: converged, or stopped at the iteration limit.
  bool HasFinitePoint() const { return usable || stopped_early; }
  // A global NLopt search that ended where its cost still falls (calibrate/fit_methods.cc,
  // NotAtAMinimum), in words; "" otherwise. Written with a warning, as stopped_early.
  std::string not_at_a_minimum;
  std::string termination;  // Ceres termination type of the last solve, e.g. CONVERGENCE
  std::string message;      // Ceres' reason for stopping
  // Summed over every solve: active-set rounds, held directions, clock-offset and noise-level
  // rounds (the evaluations are Ceres' residual and Jacobian evaluations).
  int iterations = 0;
  int evaluations = 0;
  int active_set_rounds = 0;  // solves after the first (0: the plain bounded solve converged)
  double solve_time_s = 0.0;
  double final_cost = 0.0;
  std::vector<double> parameters;
  std::vector<bool> at_bound;
  std::vector<bool> held;  // held at nominal (gauge)
  // Directions of the parameter space the training runs do not determine, held at the nominal
  // (fit/determined_directions.h), and the fit without holding them, for comparison.
  std::vector<UndeterminedDirection> held_directions;
  std::vector<double> unconstrained_parameters;
  bool unconstrained_usable = false;

  bool has_covariance = false;
  std::string covariance_message;
  double residual_sigma = 0.0;  // sqrt(|r|^2 / (3 N - n_free)), in the objective's units
  Eigen::MatrixXd covariance;   // n x n, zero rows/columns for held parameters
  // The part of `covariance` the held directions add (n x n; empty when none is held): where it
  // dominates a parameter's variance, the runs did not determine that parameter.
  Eigen::MatrixXd held_directions_covariance;
  std::vector<double> sigma;
  Eigen::MatrixXd correlation;

  // Track residuals (ModelFitOptions::track): the clock offset of each group (seconds, added to
  // the encoder time to find the ground truth's) and its sigma (0 without a covariance).
  std::vector<double> clock_offsets_s;
  std::vector<double> clock_offset_sigma_s;
  // The offsets stayed within 0.1 ms of the last ones when solved again for the final parameters
  // (they are estimated by turns with the parameters, model_fit.cc); a fit whose offsets still
  // moved is not usable (stopped_early).
  bool clock_offsets_settled = false;
  int clock_offset_iterations = 0;  // of the offsets' own small problems (not in `iterations`)
  // What the global start did (ModelFitOptions::global_start), in words; empty when the fit from
  // the nominal ended on no bound.
  std::string global_start;

  // ModelFitOptions::estimate_weights: the noise levels the weights came from (fit/noise_levels.h).
  NoiseLevels noise_levels;
};

// What the fit compares with the ground truth (fit/track_residual.h):
//   kFinalPose  each run's final pose (Palacin Eq. 14), blind to a common scale on closed loops;
//   kTrack      each run's pose from its start at checkpoints along the ground-truth path;
//   kBoth       both, each run's final pose and its mean track error weighing alike.
enum class ResidualKind { kFinalPose, kTrack, kBoth };
const char* ToString(ResidualKind kind);  // "final-pose", "track", "both"
bool ParseResidualKind(const std::string& text, ResidualKind* out);

struct ModelFitOptions {
  CeresFitOptions ceres;
  // When set, one window list per training run: the fit minimises the segment residuals
  // (relative pose error over windows, models/pose_errors.h) instead of the final poses.
  const std::vector<std::vector<Segment>>* segments = nullptr;
  // Which residuals (ignored when `segments` is set); kTrack and kBoth need `track`.
  ResidualKind residuals = ResidualKind::kFinalPose;
  const TrackFitData* track = nullptr;
  // The track residuals' weights when they differ from the final poses' (ceres.weights, which
  // they share when unset).
  std::optional<ResidualWeights> track_weights;
  // With track residuals: weigh the residual components by noise levels estimated from the fit
  // itself (fit/noise_levels.h: variance components re-estimated at the solution, each fit
  // warm-started from the last, until they settle); ceres.weights and track_weights are then
  // only the first fit's. Final poses alone keep ceres.weights (Palacin Eq. 14's 1 m : 1 rad).
  bool estimate_weights = false;
  // With estimate_weights: each session's own levels where sessions differ (fit/noise_levels.h);
  // false: one level per component for the data set.
  bool noise_levels_per_session = true;
  // When not empty, one per training run, replacing track_weights and ceres.weights for that
  // run's residuals (the per-session levels, WeightsPerRun).
  std::vector<FitWeights> weights_per_run;
  // Use the active set above (false: one plain bounded Ceres solve, as before; kept for tests
  // that show the difference).
  bool active_set_bounds = true;
  // Hold the directions the runs do not determine at the nominal (fit/determined_directions.h):
  // after the fit, the information the runs carry along every direction is weighed against the
  // bounds; when some direction stays undetermined the fit is repeated with it held.
  bool hold_undetermined = true;
  // Where that repeated fit starts: false, from the fit's own start (as every calibration is
  // written); true, from the fit without the hold moved onto it (its components along the held
  // directions set to the nominal's, ProjectOntoHold). The fit without the hold has already found
  // the determined directions, so the held fit ends in a few steps there; from the start, the
  // stiff hold made Levenberg-Marquardt crawl (the OptiOdom omni3 folds of the choice by
  // transfer: 95-197 iterations, 4-16 active-set rounds, against 15-20 from the projection) and on
  // the tricycle's final-pose fold stop on a bound at cost 103 where the projection's start finds
  // 0.058 (docs/speed.md). The fits of the choices by transfer use it.
  bool held_fit_from_projection = false;
  // When set and not empty: groups of parameters sharing one value and parameters held at the
  // nominal (fit/parameter_tying.h). The fit runs on the tied model and its result is mapped back
  // (ExpandTiedResult); every residual kind above works with it.
  const ParameterTying* tying = nullptr;
  // Far from the guess: when the fit from the guess ends with a free parameter on a bound of
  // its box (a guess several times off pulls the others there), or with residuals so far above
  // the noise that its own sigma of a free parameter is wider than the box's (a local minimum:
  // kGlobalStartSigmaRatio), fit again from points spread across the box (its centre, a quarter
  // and three quarters of the way from each free parameter's lower bound; the first whose fit
  // leaves neither ends the search) and keep the lowest cost. The sigma test needs the
  // covariance (ceres.compute_covariance). FitModel only; FitModelFrom fits from its start.
  bool global_start = true;
};

// The global start's second trigger: a free parameter's sigma above this many times its box's
// standard deviation (width / sqrt(12), the uniform prior of fit/determined_directions.h): at
// the residual level the fit left, the runs would say less about it than its bounds do.
inline constexpr double kGlobalStartSigmaRatio = 1.0;

// A value rests on a bound when it is within 1e-6 of the box's width of it: far above the YAML's
// 10 significant digits (1e-11 m on a 0.2 m distance), far below any meaningful change.
bool AtBound(double value, const Interval& box);
// Which parameters (robot().parameters order) rest on a bound of the robot's box (AtBound).
std::vector<bool> ParametersAtBound(const Robot& robot, const std::vector<double>& p);

// The clock offsets of `options.track`'s groups with the parameters held at `p` (each group's
// own bounded problem, as FitModel solves them). For `report` and `diagnose`, which replay given
// parameters against a ground truth on another clock.
std::vector<double> EstimateClockOffsets(const RobotModelInterface& model,
                                         const std::vector<double>& p,
                                         const ModelFitOptions& options);

// The parameters the training runs did not determine: the held directions (ModelFitResult::
// held_directions_covariance) make more than half of their variance, so the bounds say more
// about them than the runs do. Per parameter; all false without held directions.
std::vector<bool> NotDeterminedParameters(const ModelFitResult& fit);

// Throws std::invalid_argument for invalid options or no runs.
ModelFitResult FitModel(const std::vector<AlignedRun>& training, const RobotModelInterface& model,
                        const ModelFitOptions& options = {});

// A fit of `tied` (parameters q) in the inner model's parameters p = A q: parameters, at_bound,
// held and the held directions per member of each group, the covariance A C_q A^T (a tied
// parameter's sigma is its shared value's; members correlate with 1).
ModelFitResult ExpandTiedResult(const TiedModel& tied, const ModelFitResult& fit);

// The fit from `start` alone (e.g. a closed-form calibration): no global start.
ModelFitResult FitModelFrom(const std::vector<AlignedRun>& training,
                            const RobotModelInterface& model, const std::vector<double>& start,
                            const ModelFitOptions& options = {});

// The parameters of the fit of the runs' relative motion over disjoint 0.5 m windows of their
// ground truth, from the nominal (`options` otherwise as given, no global start): a start for a fit
// of tracks from a guess far off. nullopt when a run was aligned without its track, with fewer
// than 4 windows in all, or when the fit has no finite point.
std::optional<std::vector<double>> FitOfDisjointWindows(const std::vector<AlignedRun>& training,
                                                        const RobotModelInterface& model,
                                                        const ModelFitOptions& options);

// The gradient of the fit's cost (the runs' residuals as FitModel weighs them) at `p`, one entry
// per parameter of `model`, held ones included: what the active set's release test reads. (From a
// problem with the held parameters fixed, Ceres gives the free entries alone.)
std::vector<double> FitCostGradient(const std::vector<AlignedRun>& training,
                                    const RobotModelInterface& model, std::vector<double> p,
                                    const ModelFitOptions& options = {});

}  // namespace fitcal
