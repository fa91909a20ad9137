#pragma once
// Text of the validation report (`fitcal report`): index.html (one self-contained file with
// inline SVG figures, no network), summary.md, metrics.csv and metrics.json. Pure formatting:
// the caller (tools/report_command.cc) computes every number with fit/, validation/ and diagnosis/
// and fills ReportData with plain values; nothing here knows a solver. Angles are radians in
// ReportData and degrees in the outputs (columns ending _deg).

#include <string>
#include <vector>

#include "io/svg_plot.h"

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
bool GotWorse(const ReportRun& run);

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
  std::vector<ReportFold> folds;
  ReportStatistics cv_cf_after, cv_cf_before;
};

// The report's figures, each a complete inline <svg>; index.html embeds all of them. Exposed so
// that tests can check each is present.
struct ReportFigures {
  std::string flower;
  std::string end_points;
  std::string residual_histogram;  // final position errors against the noise floor
  std::string final_distance_bars;
  std::string final_angle_bars;
  std::string correlation;  // empty without a correlation matrix
  // The worst runs (largest calibrated CF, at most worst_runs_drawn), worst first.
  std::vector<std::string> error_along_time;
  std::vector<std::size_t> error_along_time_runs;  // their indices in ReportData::runs
  // Error against distance travelled: position, then heading; each nominal beside calibrated
  // (every held-out run thin, the median and quartile band over runs thick).
  std::string position_error_along_distance;
  std::string heading_error_along_distance;
  // Drift per window (every drift length), translation % and rotation deg/m, as box plots.
  std::string drift_translation_boxes;
  std::string drift_rotation_boxes;
  // Held-out runs drawn with their odometry coloured by its position error (evo's picture),
  // nominal beside calibrated with the ground truth in each; worst calibrated CF first.
  std::vector<std::string> coloured_tracks;
  std::vector<std::size_t> coloured_track_runs;
};
ReportFigures MakeReportFigures(const ReportData& data);

std::string ReportHtml(const ReportData& data);
std::string ReportMarkdown(const ReportData& data);
std::string MetricsCsv(const ReportData& data);
std::string MetricsJson(const ReportData& data);

// Shared by the pages of `report` and `diagnose` (io/diagnose_page.h): one style sheet (readable
// from a 390 px phone to a 1400 px desktop), JSON scalars.
std::string PageStyleSheet();
std::string JsonStringOf(const std::string& text);
std::string JsonNumberOf(double value);  // null when not finite

// The layout version of metrics.json (docs/metrics_json.md): raised when a key changes meaning
// or disappears; keys may be added within a version.
constexpr int kMetricsJsonVersion = 2;

}  // namespace fitcal::io
