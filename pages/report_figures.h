#pragma once
// The SVG renderer of the report: each figure of index.html drawn from the model
// (pages/report_model.h), a complete inline <svg>.

#include <cstddef>
#include <string>
#include <vector>

#include "pages/report_model.h"

namespace fitcal::io {

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

}  // namespace fitcal::io
