#pragma once
// Never worse than the nominal, judged with the runs' own scatter (docs/never_worse.md). A
// calibration is written only if, on the held-out runs as a whole and on each kind of run
// (trajectory family), none of the measures a user compares - CF (Palacin Eq. 14), ATE RMSE
// (Eq. 12), drift per 1, 2 and 5 m of path (translation %) - is worse than the nominal's beyond
// what re-recording the same runs would change. Drift per family, and over 0.5 m windows, is
// judged by the same rule and warns instead of refusing (measured on the real diff drive:
// docs/never_worse.md).
//
// The rule (one for fit, diagnose, export and generalise): for a measure with per-run values
// x_i (nominal) and y_i (calibration) on the same n runs, weights w_i (drift: the run's windows;
// else 1) and means X = sum w x / sum w, Y likewise, the calibration is worse when
//     Y - X > margin = t_{1 - alpha/k, dof} * s * (X + Y) / 2 * sqrt(2 / n_eff),
// where s is the relative spread of one run's value between repetitions of the same trajectory
// (label): s^2 = sum over labels and both calibrations of (v_i / mean_label - 1)^2, divided by
// dof = the sum of (runs of the label - 1); n_eff = (sum w)^2 / sum w^2 (n for equal weights);
// alpha = 0.05 shared by the k comparisons of one judgement (Bonferroni), so that a calibration
// that is truly no worse is refused by any of them at most 5 % of the time when the runs scatter
// as their repetitions say. This is the one-sided two-sample t test of the two means with the
// repetitions' pooled spread: it does not pair the runs, because a fitted calibration's own
// estimation error shifts every run of a family alike - a paired test would call that shift,
// which the noise put there, significant. A family without repeated labels borrows the spread of
// all the held-out runs; when no label repeats at all, the runs of each family stand in for
// repetitions (a wider margin: their scatter holds the paths' differences too); with no family of
// two runs the spread is not measured, the margin is 0 and the line says so (the strict
// comparison of before).

#include <map>
#include <string>
#include <vector>

#include "fit/result_gate.h"
#include "odometry/aligned_run.h"
#include "odometry/run_log.h"
#include "validation/everyday_driving.h"
#include "validation/verdict.h"

namespace fitcal {

// The family-wise false-refusal rate the margins are set for.
inline constexpr double kNeverWorseAlpha = 0.05;

// The relative spread of one run's value between repetitions (s above) and its degrees of
// freedom; dof 0: not measured.
struct RepetitionSpread {
  double relative_sd = 0.0;
  int dof = 0;
};

struct NeverWorseJudgement {
  std::string measure;  // "CF", "ATE RMSE [m]", "drift 1 m [%]"
  std::string runs;     // "held-out 'spinR' runs (2)", "held-out runs (20)"
  double nominal = 0.0;
  double calibrated = 0.0;
  double margin = 0.0;  // calibrated may exceed nominal by this before it is worse
  RepetitionSpread spread;
  double t = 0.0;  // the quantile used
  // Whether being worse refuses the calibration (else a warning): drift per family and over
  // windows shorter than 1 m warn only.
  bool refuses = true;
  bool all_runs = false;  // judged on all the held-out runs, not on one family of them
  bool Worse() const { return calibrated > nominal + margin; }
  bool Refuses() const { return refuses && Worse(); }
  // Risen by more than kRegressionTolerance (the report's 5 %) of the nominal's value, yet inside
  // the margin: written, and said, so that a rise is not read as a pass (issue 42: the circles-only
  // diff fit's squares, drift 1 m 0.740 -> 0.836 %, +13 %, margin 0.16, went unsaid).
  bool WorseWithinScatter() const {
    return !Worse() && calibrated > nominal * (1.0 + kRegressionTolerance);
  }
  // "CF 0.0032 -> 0.0036, more than the margin 0.0012 (t 4.5 x spread 11 % of a run's value
  // between repetitions, 2 dof)"; "within the margin" when not Worse().
  std::string Description() const;
};

// One measure on one set of runs: values and weights per run, `k` comparisons sharing alpha.
NeverWorseJudgement JudgeMeasure(const std::string& measure, const std::string& runs,
                                 const std::vector<std::string>& labels,
                                 const std::vector<double>& weights,
                                 const std::vector<double>& nominal,
                                 const std::vector<double>& calibrated,
                                 const RepetitionSpread& fallback, int k);

// Every comparison of the calibration with the nominal on `runs` (the held-out runs, in the
// order both metrics were evaluated on): CF, ATE and drift at each length with windows, on all
// the runs and, when they hold two or more families, on each family. Metrics without per-run
// values (a final-pose-only judge) give CF alone. The judgements in that order; Worse() marks a
// refusal.
std::vector<NeverWorseJudgement> JudgeNeverWorse(const std::vector<AlignedRun>& runs,
                                                 const EverydayDrivingMetrics& nominal,
                                                 const EverydayDrivingMetrics& calibrated);

// A calibration beside the nominal for everyday driving on `runs` (tracks[i] is runs[i]'s ground
// truth): both replayed once at EverydayDriftLengths(), the never-worse judgements of the
// calibration and the rows of the table `fit` and `generalise` print (EverydayDrivingRows, a
// measure that rose noted with the runs' scatter, NeverWorseRowNotes).
struct EverydayDrivingComparison {
  std::vector<NeverWorseJudgement> judgements;
  std::vector<std::string> rows;
};
EverydayDrivingComparison CompareEverydayDriving(const RobotModelInterface& model,
                                                 const CalibrationCandidate& nominal,
                                                 const CalibrationCandidate& calibrated,
                                                 const std::vector<AlignedRun>& runs,
                                                 const std::vector<const GroundTruthTrack*>& tracks,
                                                 int num_threads = 0);

// The judgements that refuse (refusing = false: those worse that only warn), as lines "'<name>'
// is worse than the nominal on the <runs>: ...".
std::vector<std::string> NeverWorseRefusals(const std::string& name,
                                            const std::vector<NeverWorseJudgement>& judgements,
                                            bool refusing = true);

// The judgements WorseWithinScatter(), as lines "'<name>' is worse than the nominal on the
// <runs>, within the runs' scatter: drift 1 m [%] 0.74 -> 0.836 (+13.0 %), within the margin ...".
std::vector<std::string> NeverWorseWithinScatter(
    const std::string& name, const std::vector<NeverWorseJudgement>& judgements);

// What a command that writes a calibration says of its never-worse judgements, one rule for fit,
// diagnose and export: `warnings` (worse where worse only warns, then risen by more than 5 %
// within the scatter), each a line to print as "warning: ...", and `refusals`, each a reason
// the calibration is not written.
struct NeverWorseSaid {
  std::vector<std::string> warnings;
  std::vector<std::string> refusals;
};
NeverWorseSaid SayNeverWorse(const std::string& name,
                             const std::vector<NeverWorseJudgement>& judgements);

// What a table row of all the held-out runs says beside a measure that rose, keyed by the
// measure's name ("ATE RMSE [m]", "drift 1 m [%]"): "worse, within the scatter: margin 0.119" or
// "worse beyond the scatter: margin 0.119"; measures that did not rise are absent.
std::map<std::string, std::string> NeverWorseRowNotes(
    const std::vector<NeverWorseJudgement>& judgements);

}  // namespace fitcal
