#include "cli/solver_options.h"
#include "cli/cli_validators.h"

#include <cmath>

#include "odometry/invalid.h"

namespace fitcal::tools {

ResidualWeights SolverOptions::Weights() const {
  ResidualWeights weights;
  weights.position_sigma_m = position_sigma_m;
  weights.heading_sigma_rad = heading_sigma_deg * M_PI / 180.0;
  return weights;
}

void AddSolverOptions(CLI::App& app, SolverOptions& o) {
  app.add_option("--objective", o.objective,
                 "squares (sum of squared residuals; Ceres default) or eq14 (sum of per-run "
                 "norms, Palacin Eq. 14; NLopt default)");
  app.add_option("--loss", o.loss, "Ceres robust loss: none, huber, cauchy")->capture_default_str();
  app.add_option("--loss-scale", o.loss_scale, "Robust loss scale (residual units: m and rad)")
      ->capture_default_str();
  app.add_option("--seed", o.seed, "NLopt random seed (same seed, same result)")
      ->capture_default_str();
  app.add_option("--max-evaluations", o.max_evaluations, "NLopt evaluation budget per fit")
      ->capture_default_str();
  app.add_option("--max-iterations", o.max_iterations, "Ceres iterations per solve")
      ->capture_default_str()
      ->check(PositiveNumber());
  app.add_flag("--polish", o.polish,
               "NLopt global methods: polish the best point with SLSQP (autodiff gradient)");
  const auto given = [&o](const std::string&) { o.sigmas_given = true; };
  app.add_option("--position-sigma-m", o.position_sigma_m,
                 "Weight of the position residual as a standard deviation (m); with the default "
                 "1 m and 57.3 deg the objective weighs metres and radians as Eq. 14")
      ->capture_default_str()
      ->check(SigmaAtLeast(1e-9, "m"))
      ->each(given);
  app.add_option("--heading-sigma-deg", o.heading_sigma_deg,
                 "Weight of the heading residual as a standard deviation (deg)")
      ->capture_default_str()
      ->check(SigmaAtLeast(1e-7, "deg"))
      ->each(given);
}

void AddTrackResidualOptions(CLI::App& app, SolverOptions& o) {
  app.add_option("--residuals", o.residuals,
                 "What the fit compares with the ground truth: final-pose (each run's end, "
                 "Palacin Eq. 14), track (the pose from the run's start every 0.5 m of "
                 "ground-truth path and at the end), both, or auto: track where the ground truth "
                 "samples the path at least every 0.1 m on runs of 2 m or more and the method is "
                 "Ceres, final-pose otherwise (docs/everyday_driving.md); track and both need a "
                 "Ceres method")
      ->capture_default_str();
  app.add_option("--clock-offsets", o.clock_offsets,
                 "Track residuals: estimate the ground-truth clock's offset per session (the "
                 "run's trajectory label; import optiodom: the recording folder), per run, one "
                 "for the whole data set, or none (held at 0)")
      ->capture_default_str();
  app.add_option("--track-heading", o.track_heading,
                 "Track residuals: the heading compared from the run's start (from-start) or as "
                 "its increment over each checkpoint spacing (increments), or auto: the one "
                 "that transfers better to runs of a kind it was not fitted on "
                 "(docs/everyday_driving.md)")
      ->capture_default_str();
  app.add_option("--weights", o.weight_mode,
                 "Track residuals: fixed (--position-sigma-m, --heading-sigma-deg) or estimated "
                 "(noise levels of position and heading estimated from the fit itself, per "
                 "session where the sessions differ, printed and written into the calibration's "
                 "objective; docs/everyday_driving.md), or auto: estimated when their fit is "
                 "lower than the fixed weights' on the held-out runs in CF, drift and ATE; "
                 "--position-sigma-m or --heading-sigma-deg given fixes them")
      ->capture_default_str()
      ->check(CLI::IsMember({"fixed", "estimated", "auto"}));
}

std::string SolverFlagThatDoesNotApply(const SolverOptions& o, const SolverOptions& defaults,
                                       bool ceres, bool nlopt, const std::string& methods) {
  const bool loss = o.loss != defaults.loss;
  if (!ceres && (loss || o.loss_scale != defaults.loss_scale)) {
    return "--loss and --loss-scale shape the Ceres methods' final-pose residuals; " + methods +
           " does not use them";
  }
  if (!ceres && o.max_iterations != defaults.max_iterations) {
    return "--max-iterations bounds the Ceres methods; " + methods + " has --max-evaluations";
  }
  if (!nlopt && (o.seed != defaults.seed || o.max_evaluations != defaults.max_evaluations ||
                 o.polish)) {
    return "--seed, --max-evaluations and --polish apply to the NLopt methods; " + methods +
           " does not use them";
  }
  if (!loss && o.loss_scale != defaults.loss_scale) {
    return "--loss-scale without --loss (huber or cauchy) has no loss to scale";
  }
  return "";
}

bool MakeFitMethodSettings(const SolverOptions& o, int threads, FitMethodSettings* s,
                           std::string* error) {
  s->threads = threads;
  s->max_iterations = o.max_iterations;
  s->weights = o.Weights();
  s->estimate_weights = o.weight_mode == "estimated" && !o.sigmas_given;
  s->weights_auto = o.weight_mode == "auto" && !o.sigmas_given;  // a sigma given fixes them
  s->objective_set = !o.objective.empty();
  if (s->objective_set && !ParseFinalPoseObjective(o.objective, &s->objective))
    return Invalid(error, "unknown --objective '" + o.objective + "' (available: squares, eq14)");
  s->residuals_auto = o.residuals == "auto";
  if (!s->residuals_auto && !ParseResidualKind(o.residuals, &s->residuals)) {
    *error =
        "unknown --residuals '" + o.residuals + "' (available: auto, final-pose, track, both)";
    return false;
  }
  if (!ParseClockGrouping(o.clock_offsets, &s->clock_grouping)) {
    *error = "unknown --clock-offsets '" + o.clock_offsets +
             "' (available: session, run, dataset, none)";
    return false;
  }
  s->track_heading_auto = o.track_heading == "auto";
  if (!s->track_heading_auto && !ParseTrackHeading(o.track_heading, &s->track_heading)) {
    *error = "unknown --track-heading '" + o.track_heading +
             "' (available: from-start, increments, auto)";
    return false;
  }
  if (!ParseCeresRobustLoss(o.loss, &s->loss))
    return Invalid(error, "unknown --loss '" + o.loss + "' (available: none, huber, cauchy)");
  s->loss_scale = o.loss_scale;
  s->seed = o.seed;
  s->max_evaluations = o.max_evaluations;
  s->local_polish = o.polish;
  if (o.max_evaluations < 1) return Invalid(error, "--max-evaluations must be positive");
  if (!(o.loss_scale > 0.0)) return Invalid(error, "--loss-scale must be positive");
  return true;
}

}  // namespace fitcal::tools
