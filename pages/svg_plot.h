#pragma once
// Small, self-contained SVG charts for the HTML report: x-y line/marker plots, grouped bar
// charts and a heat map. The output is an inline <svg> element (no xmlns, no external fonts,
// images or style sheets), so an HTML file that embeds it needs nothing else to display.
// Every chart has a title, axis labels (the caller puts the unit in them: "x [m]") and a legend.

#include <string>
#include <vector>

namespace fitcal::io {

// Escapes &, <, >, " and ' for XML text and attribute values.
std::string EscapeXml(const std::string& text);

// "Nice" tick positions (1, 2, 5 x 10^n steps) covering [lo, hi], at most about max_ticks.
std::vector<double> NiceTicks(double lo, double hi, int max_ticks = 7);

// The q-quantile of v, linear between order statistics; NaN for none. What the report's figures
// range their axes by and its error-against-distance bands are drawn from.
double Quantile(std::vector<double> v, double q);

struct Point2 {
  double x = 0.0;
  double y = 0.0;
};

// One legend entry; may hold several polylines (e.g. every validation run of a kind).
struct SvgSeries {
  std::string name;
  std::string color = "#000000";
  std::vector<std::vector<Point2>> lines;
  bool draw_lines = true;
  bool draw_markers = false;
  double line_width = 1.5;
  double marker_radius = 3.0;
  double opacity = 1.0;
  std::string dash;  // SVG stroke-dasharray, e.g. "4 3"; empty = solid
  // Non-empty: each line is a closed polygon filled with this colour (at `opacity`), e.g. the
  // band between two quantiles; no stroke.
  std::string fill;
  // Non-empty (one value per point of each line): the line is drawn in pieces coloured by the
  // value on a viridis scale from value_lo to value_hi (evo's error-coloured track; svg_plot.cc).
  std::vector<std::vector<double>> values;
  double value_lo = 0.0, value_hi = 1.0;
};

// A horizontal colour bar of that viridis scale from lo to hi, labelled, `width` pixels wide.
std::string ColourBarSvg(const std::string& label, double lo, double hi, int width = 360);

struct XYPlotOptions {
  std::string title;
  std::string x_label;
  std::string y_label;
  int width = 640;
  int height = 440;
  bool equal_aspect = false;  // one metre is as long on x as on y (trajectories)
  bool include_origin = false;
  // Unique id prefix within the embedding document (for the clip path); empty = a counter.
  std::string id;
  // Optional fixed ranges (used when lo < hi).
  double x_lo = 0.0, x_hi = 0.0, y_lo = 0.0, y_hi = 0.0;
};

std::string XYPlotSvg(const XYPlotOptions& options, const std::vector<SvgSeries>& series);

struct BarSeries {
  std::string name;
  std::string color;
  std::vector<double> values;  // one per category
};

struct BarChartOptions {
  std::string title;
  std::string x_label;
  std::string y_label;
  int width = 1100;
  int height = 360;
};

// Grouped bars: for each category one bar per series, side by side. Category labels that do not
// fit their group's width side by side are written slanted, with the figure grown to hold them.
std::string BarChartSvg(const BarChartOptions& options, const std::vector<std::string>& categories,
                        const std::vector<BarSeries>& series);

// Box plots: for each category one box per series, side by side: the box from the first to the
// third quartile, the median a line across it, whiskers to the farthest value within 1.5
// interquartile ranges, values beyond them as dots (at most a few hundred drawn).
struct BoxSeries {
  std::string name;
  std::string color;
  std::vector<std::vector<double>> samples;  // one vector per category
};
std::string BoxPlotSvg(const BarChartOptions& options, const std::vector<std::string>& categories,
                       const std::vector<BoxSeries>& series);

// Estimated width in pixels of `text` at `font_px` in a sans-serif font (0.6 em per character,
// a little wide for most glyphs): for laying out labels that must not overlap.
double TextWidthPx(const std::string& text, double font_px);

// Square matrix as coloured cells with the value printed in each: blue for lo, white for the
// middle, red for hi; a colour bar explains the scale.
std::string HeatMapSvg(const std::string& title, const std::vector<std::string>& labels,
                       const std::vector<std::vector<double>>& values, double lo = -1.0,
                       double hi = 1.0, int cell_px = 46);

}  // namespace fitcal::io
