#pragma once
// The model of the validation report (`fitcal report`): plain values, built once from the data by
// validation/report_builder.h (which computes every number with fit/, validation/ and diagnosis/),
// then formatted by one renderer per output (pages/report_html.h, report_markdown.h, report_json.h,
// report_csv.h, report_tum.h, report_figures.h). Nothing here computes. Angles are radians in the
// model and degrees in the outputs (columns ending _deg).

#include <algorithm>
#include <string>
#include <vector>

#include "pages/svg_plot.h"
#include "odometry/pose2.h"

namespace fitcal::io {

// Palacin Table 6 quantities of one run, or their average over runs.
struct ReportMetrics {
  double rms_distance_m = 0.0;    // Eq. 12
  double rms_angle_rad = 0.0;     // Eq. 13
  double max_distance_m = 0.0;    // Eq. 10
  double max_angle_rad = 0.0;     // Eq. 11
  double final_distance_m = 0.0;  // final position error
  double final_angle_rad = 0.0;   // final |heading error|
  double cf = 0.0;                // Eq. 14
};

struct ReportRun {
  std::string id;
  std::string trajectory;
  int repetition = 0;
  double path_length_m = 0.0;  // ground-truth path length over the window
  // Along the run at the ground-truth times, in the run's start frame (start pose at the origin,
  // heading along +x) so that all runs draw the flower of Palacin Fig. 9.
  std::vector<double> t_s;  // since the start of the window
  // Ground-truth distance travelled from the start of the window to each t_s sample (m): the
  // x axis of the error-against-distance figures. Empty: the run is left out of them.
  std::vector<double> along_m;
  std::vector<Point2> ground_truth_xy, before_xy, after_xy;
  std::vector<double> before_distance_m, after_distance_m;  // Eq. 8
  std::vector<double> before_angle_rad, after_angle_rad;    // Eq. 9
  // Final odometry minus final ground truth, in the start frame (m), and the signed final heading
  // error wrap(theta_odometry - theta_ground_truth) (rad).
  Point2 before_final_error, after_final_error;
  double before_final_heading_rad = 0.0, after_final_heading_rad = 0.0;
  ReportMetrics before, after;  // before.rms_distance_m is the run's ATE RMSE (no alignment)
};

// A held-out run got worse with the calibration: its CF (Eq. 14) or its ATE RMSE (Eq. 12, the
// odometry started at the ground truth's start pose, no other alignment) rose. The page flags
// it, metrics.json carries it per run.
inline bool GotWorse(const ReportRun& run) {
  return run.after.cf > run.before.cf || run.after.rms_distance_m > run.before.rms_distance_m;
}

// Table 6 rows: one per trajectory family and one overall.
struct ReportSummaryRow {
  std::string group;
  int runs = 0;
  ReportMetrics before, after;
};

// evo-style statistics of one per-run quantity over the validation runs.
struct ReportStatistics {
  double rmse = 0.0, mean = 0.0, median = 0.0, std = 0.0, min = 0.0, max = 0.0;
};
struct ReportStatisticsRow {
  std::string metric;     // e.g. "final_distance_m"
  bool is_angle = false;  // values in rad, shown in deg
  ReportStatistics before, after;
};

struct ReportParameter {
  std::string name;       // "R_a"
  bool at_bound = false;  // resting on a bound of the robot's box
  std::string unit;       // "m" or "deg" (display unit; values below are in SI + rad)
  bool is_angle = false;
  bool is_position = false;  // a frame's x or y: where, not how big, so it changes by metres
  bool held = false;  // held at its nominal value by the robot YAML: not fitted, no sigma
  double nominal = 0.0;
  double calibrated = 0.0;
  bool has_sigma = false;
  double sigma = 0.0;
  bool has_cv = false;
  double cv_mean = 0.0, cv_std = 0.0, cv_min = 0.0, cv_max = 0.0;
};

struct ReportFold {
  int held_out_repetition = 0;
  bool usable = false;
  double cf_training = 0.0;
  double cf_validation_before = 0.0;
  double cf_validation_after = 0.0;
};

// The verdict (validation/verdict.h) as text: level "PASS", "WARN" or "FAIL" per reason.
struct ReportVerdictReason {
  std::string level;
  std::string check;    // machine-readable name of the check
  std::string section;  // id of the report section it refers to
  std::string message;
};

// An effect the calibration carries beyond the model's parameters (odometry/effects.h).
struct ReportEffect {
  std::string name;
  std::vector<std::string> parameter_names;
  std::vector<double> values, sigmas;  // as the YAML records them (SI and rad)
};

// Drift per distance travelled: the relative pose error over windows of one ground-truth path
// length (KITTI's odometry metric, evo_rpe with --delta in metres), mean over every window of every
// validation run.
struct ReportDriftRow {
  double length_m = 0.0;
  int windows = 0;
  double before_translation_percent = 0.0, after_translation_percent = 0.0;
  double before_rotation_rad_per_m = 0.0, after_rotation_rad_per_m = 0.0;
  // Every window, for the box plots (same windows before and after: they are chosen on the
  // ground truth); empty when only the means are known.
  std::vector<double> before_translation_percent_windows, after_translation_percent_windows;
  std::vector<double> before_rotation_rad_per_m_windows, after_rotation_rad_per_m_windows;
  int windows_worse = 0;  // windows whose translation error rose with the calibration
  // When the translation drift rose: whether the runs' scatter explains it, as fit says it
  // (validation/never_worse.h: "worse, within the scatter: margin 0.124"); empty otherwise.
  std::string never_worse_note = {};
};

// Mean signed final error (bias) over the validation runs in each run's start frame: what a
// constant offset of the odometry looks like, which the absolute errors hide.
struct ReportBias {
  double x_m = 0.0, y_m = 0.0, heading_rad = 0.0;
};

// The error of the runs against the distance the ground truth travelled, summarised over the
// runs that reach each distance: the quartiles and the median on a grid of distances up to
// where half the runs still go (the band of the error-against-distance figures). Values in the
// error's unit (m, or rad for the heading).
struct ReportErrorBand {
  std::vector<double> distance_m, lower_quartile, median, upper_quartile;
};
struct ReportErrorBands {
  ReportErrorBand position_before, position_after;  // Eq. 8
  ReportErrorBand heading_before, heading_after;    // Eq. 9, |heading error|
};

// The repeatability test of the calibrated final position errors (validation/verdict.h).
struct ReportNoiseFloor {
  bool available = false;
  double noise_sigma_m = 0.0;  // per axis
  double systematic_rms_m = 0.0;
  double f_statistic = 0.0, p_value = 1.0;
};

// One calibration of a comparison (`report --calibration a.yaml --calibration b.yaml`), all on
// the same validation runs.
struct ReportComparisonRow {
  std::string calibration;
  std::string verdict;
  std::string training_source;
  ReportSummaryRow all;                     // all validation runs, nominal and this calibration
  std::vector<double> trajectory_cf_after;  // in the order of ReportData::trajectories
  ReportDriftRow drift;                     // the longest window length
};

// One judged run in the world frame at the ground-truth times, as the metrics were computed on it
// (the odometry started at the ground truth's start pose): what `report --tum` writes.
struct ReportWorldTrack {
  std::string run_id;
  std::vector<double> t_s;  // ground-truth times (the log's clock)
  std::vector<Pose2d> ground_truth, nominal, calibrated;
};

struct ReportData {
  std::string tool_version;
  std::string dataset;
  std::string calibration;
  std::string robot_name;
  std::string sampling;  // "nearest" or "linear"
  std::string verdict;   // "PASS", "WARN" or "FAIL"
  std::vector<ReportVerdictReason> verdict_reasons;
  // Effects the calibration carries beyond the model's parameters, replayed in "after"; empty for
  // the parameters alone. With effects, cf_parameters_only is the held-out CF (all runs) of the
  // calibrated parameters replayed without them.
  std::vector<ReportEffect> effects;
  double cf_parameters_only = 0.0;
  // Where the training runs are: e.g. "180 runs of this data set (recorded by id)" or "another
  // data set (data/circles): every run here validates".
  std::string training_source;
  // What produced the calibration, as its YAML records it (method, solver termination).
  std::string calibration_note;
  std::string training_repetitions;
  std::string validation_repetitions;
  int training_runs = 0;
  // Every calibration compared, this one first; empty for a report of one calibration.
  std::vector<ReportComparisonRow> comparison;
  std::vector<ReportRun> runs;  // validation runs
  // The error-along-time figures are drawn for the runs with the largest calibrated CF, at most
  // this many (every run is in the tables and in metrics.csv).
  int worst_runs_drawn = 8;
  std::vector<ReportSummaryRow> summary;
  std::vector<ReportSummaryRow> trajectories;  // one row per trajectory label
  std::vector<ReportDriftRow> drift;
  // fit's never-worse judgement on these runs: each measure (CF, ATE, drift) and family that is
  // worse than the nominal, beyond the runs' scatter or more than 5 % within it, in one line.
  std::vector<std::string> never_worse_lines;
  ReportBias bias_before, bias_after;
  ReportErrorBands error_bands;
  ReportNoiseFloor noise_floor;
  std::vector<ReportStatisticsRow> statistics;
  std::vector<ReportParameter> parameters;
  std::string uncertainty_note;  // how sigma was obtained, or why there is none
  bool has_correlation = false;
  std::vector<std::vector<double>> correlation;
  bool identifiability_checked = true;  // false when the training runs are not in this data set
  bool identifiable = true;
  double condition_number = 0.0;
  std::vector<std::string> identifiability_lines;
  bool has_cv = false;
  std::string cv_objective;  // what each fold minimises, in words (the calibration's may differ)
  std::vector<ReportFold> folds;
  ReportStatistics cv_cf_after, cv_cf_before;
  std::vector<ReportWorldTrack> world_tracks;  // one per validation run, in the order of runs
};

// The held-out runs that got worse (GotWorse): the page's key numbers, metrics.json, `report`.
inline int WorseRunCount(const ReportData& data) {
  return static_cast<int>(std::count_if(data.runs.begin(), data.runs.end(), GotWorse));
}

}  // namespace fitcal::io
