#include "pages/final_error_plot.h"

namespace fitcal::io {

namespace {
const char* const kNominalColour = "#d55e00";  // vermillion: nominal parameters
const char* const kCalibratedColour = "#0072b2";  // blue: calibrated parameters
}  // namespace

std::string FinalErrorScatterSvg(const FinalErrorScatter& s) {
  SvgSeries before, after, origin;
  before.name = s.before_name;
  before.color = kNominalColour;
  after.name = s.after_name;
  after.color = kCalibratedColour;
  origin.name = s.origin_name;
  origin.lines = {{Point2{0.0, 0.0}}};
  origin.opacity = s.origin_opacity;
  origin.marker_radius = s.origin_marker_radius;
  for (SvgSeries* series : {&before, &after, &origin}) {
    series->draw_lines = false;
    series->draw_markers = true;
  }
  for (SvgSeries* series : {&before, &after}) {
    series->opacity = s.run_opacity;
    series->lines.emplace_back();
  }
  for (const Point2& e : s.before_m) before.lines[0].push_back({1e3 * e.x, 1e3 * e.y});
  for (const Point2& e : s.after_m) after.lines[0].push_back({1e3 * e.x, 1e3 * e.y});
  XYPlotOptions o = s.plot;
  o.equal_aspect = true;
  o.include_origin = true;
  return XYPlotSvg(o, {before, after, origin});
}

}  // namespace fitcal::io
