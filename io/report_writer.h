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
  // Along the run at the ground-truth times, in the run's start frame (start pose at the origin,
  // heading along +x) so that all runs draw the flower of Palacin Fig. 9.
  std::vector<double> t_s;  // since the start of the window
  std::vector<Point2> ground_truth_xy, before_xy, after_xy;
  std::vector<double> before_distance_m, after_distance_m;  // Eq. 8
  std::vector<double> before_angle_rad, after_angle_rad;    // Eq. 9
  // Final odometry minus final ground truth, in the start frame (m).
  Point2 before_final_error, after_final_error;
  ReportMetrics before, after;
};

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
  std::string name;  // "R_a"
  std::string unit;  // "m" or "deg" (display unit; values below are in SI + rad)
  bool is_angle = false;
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

struct ReportData {
  std::string tool_version;
  std::string dataset;
  std::string calibration;
  std::string robot_name;
  std::string sampling;  // "nearest" or "linear"
  // Effects the calibration carries beyond the nine parameters, replayed in "after", one
  // description each (e.g. "time_offset: latency_s = 0.08"); empty for the nine alone.
  std::vector<std::string> calibrated_effects;
  std::string training_repetitions;
  std::string validation_repetitions;
  int training_runs = 0;
  std::vector<ReportRun> runs;  // validation runs
  std::vector<ReportSummaryRow> summary;
  std::vector<ReportStatisticsRow> statistics;
  std::vector<ReportParameter> parameters;
  std::string uncertainty_note;  // how sigma was obtained, or why there is none
  bool has_correlation = false;
  std::vector<std::vector<double>> correlation;
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
  std::string final_distance_bars;
  std::string final_angle_bars;
  std::string correlation;                    // empty without a correlation matrix
  std::vector<std::string> error_along_time;  // one per run, same order as ReportData::runs
};
ReportFigures MakeReportFigures(const ReportData& data);

std::string ReportHtml(const ReportData& data);
std::string ReportMarkdown(const ReportData& data);
std::string MetricsCsv(const ReportData& data);
std::string MetricsJson(const ReportData& data);

}  // namespace fitcal::io
