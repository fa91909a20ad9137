#pragma once
// The solver settings of every command that fits (fit, compare), in one options struct with its
// defaults in the class, declared as flags once (AddSolverOptions) and checked once
// (MakeFitMethodSettings, below) before anything is read. Each method uses the
// settings that apply to it: Ceres the objective, loss and iterations; NLopt the objective, seed,
// budget and polish; both the residual weights.

#include <CLI/CLI.hpp>
#include <string>

#include "calibrate/fit_methods.h"
#include "models/model_interface.h"

namespace fitcal::tools {

struct SolverOptions {
  std::string objective;        // "" = the method's default; "squares" or "eq14"
  // What the residuals compare (fit/model_fit.h ResidualKind): final-pose, track, both, or auto
  // (fit/residual_choice.h: track on dense ground-truth tracks with a Ceres method).
  std::string residuals = "auto";
  // Track residuals: one clock offset per session, run, data set, or none (all held at 0).
  std::string clock_offsets = "none";
  // Track residuals: the heading from the run's start, its increments between checkpoints, or
  // auto: the one that transfers better to a kind of run it was not fitted on
  // (validation/track_objective_transfer.h; from the start unless increments are better on the
  // pooled CF, drift and ATE alike).
  std::string track_heading = "auto";
  std::string loss = "none";    // Ceres: none, huber, cauchy
  double loss_scale = 0.05;     // Ceres robust loss scale, residual units
  unsigned long seed = 1;       // NLopt
  int max_evaluations = 20000;  // NLopt, the whole fit
  int max_iterations = 100;     // Ceres iterations per solve
  bool polish = false;          // NLopt global methods: SLSQP polish of the best point
  // The residual's weights as standard deviations; 1 m and 1 rad weigh metres and radians as
  // Palacin Eq. 14's CF does. With weight_mode = "estimated", track residuals (and `both`) are
  // weighed by noise levels estimated from the fit (fit/noise_levels.h) unless a sigma is given
  // (sigmas_given). Default "auto": the estimated weights replace the fixed ones when their fit
  // is lower on the held-out runs in CF, drift and ATE (calibrate/choice_by_transfer.h).
  std::string weight_mode = "auto";
  double position_sigma_m = 1.0;
  double heading_sigma_deg = 180.0 / 3.14159265358979323846;
  // Set when either sigma is given: the weights are then these, not estimated from the data.
  bool sigmas_given = false;

  ResidualWeights Weights() const;  // the sigmas in SI units (the heading's in radians)
};

// Declares the solver flags on `app`, bound to `options`; each shows its default.
void AddSolverOptions(CLI::App& app, SolverOptions& options);
// What the track residual needs beyond them (--residuals, --clock-offsets, --track-heading,
// --weights): declared only by a command that fits tracks (fit), so that another (compare, which
// fits final poses) refuses them as flags it does not take (exit 2) instead of ignoring them.
void AddTrackResidualOptions(CLI::App& app, SolverOptions& options);

// A solver flag none of the methods would use, as the flags alone show it: "" or the refusal's one
// line (exit 2), so that nothing the user set is dropped without a word. `ceres` and `nlopt` say
// whether the methods asked for (`methods`, e.g. "--method ceres") include a Ceres and an NLopt
// one; `defaults` are the command's (a flag given at its default changes nothing either way).
std::string SolverFlagThatDoesNotApply(const SolverOptions& o, const SolverOptions& defaults,
                                       bool ceres, bool nlopt, const std::string& methods);

// The solver flags (cli/solver_options.h) checked and turned into settings; false with a
// one-line message when a name is unknown or a value out of range.
bool MakeFitMethodSettings(const SolverOptions& options, int threads, FitMethodSettings* settings,
                           std::string* error);

}  // namespace fitcal::tools
