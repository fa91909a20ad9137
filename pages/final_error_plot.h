#pragma once
// The scatter of the runs' final position errors, nominal and calibrated, around the ground
// truth's end point at the origin, in each run's start frame (mm): the report's "zoom on the end
// points" and diagnose's "held-out final position errors" are this one figure, styled apart.

#include <string>
#include <vector>

#include "pages/svg_plot.h"

namespace fitcal::io {

struct FinalErrorScatter {
  // id, title, axis labels and size; the plot is always drawn with equal aspect and the origin.
  XYPlotOptions plot;
  std::string before_name, after_name, origin_name;
  // Final odometry minus final ground truth in the run's start frame (m), one point per run.
  std::vector<Point2> before_m, after_m;
  double run_opacity = 0.7;
  double origin_opacity = 1.0;
  double origin_marker_radius = 3.0;
};

std::string FinalErrorScatterSvg(const FinalErrorScatter& scatter);

}  // namespace fitcal::io
