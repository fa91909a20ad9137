#include "pages/report_figures.h"

#include <algorithm>
#include <cmath>

#include "pages/final_error_plot.h"
#include "pages/report_text.h"
#include "pages/svg_plot.h"
#include "odometry/text_format.h"

namespace fitcal::io {

namespace {

using namespace report_text;

SvgSeries Series(const std::string& name, const std::string& colour) {
  SvgSeries s;
  s.name = name;
  s.color = colour;
  return s;
}

// Indices 0..n-1 thinned to at most `most`, evenly strided, first and last kept.
std::vector<std::size_t> ThinnedIndices(std::size_t n, std::size_t most) {
  std::vector<std::size_t> out;
  if (n <= most || most < 2) {
    for (std::size_t i = 0; i < n; ++i) out.push_back(i);
    return out;
  }
  const double step = static_cast<double>(n - 1) / static_cast<double>(most - 1);
  for (std::size_t i = 0; i < most; ++i) {
    out.push_back(static_cast<std::size_t>(std::lround(step * static_cast<double>(i))));
  }
  return out;
}

// At most `most` points of a polyline for drawing (ThinnedIndices): a run logged at 100 Hz has
// far more points than a 600-pixel figure can show, and the real-data report must stay small
// (README: under 2 MB for the OptiOdom omni3 set).
std::vector<Point2> Thinned(const std::vector<Point2>& line, std::size_t most) {
  std::vector<Point2> out;
  for (std::size_t i : ThinnedIndices(line.size(), most)) out.push_back(line[i]);
  return out;
}

// Points per polyline of the figure of every run: ~40,000 points in all (~0.6 MB of SVG), at
// least 40 per run so that a circle still looks round.
std::size_t PointsPerRun(std::size_t runs, std::size_t lines_per_run) {
  const std::size_t total = 40000;
  return std::max<std::size_t>(
      40, std::min<std::size_t>(400, total / std::max<std::size_t>(1, runs * lines_per_run)));
}

std::string ErrorAlongTimeSvgs(const ReportRun& r, std::size_t k) {
  SvgSeries bd = Series(kBeforeName, kBeforeColour), ad = Series(kAfterName, kAfterColour);
  SvgSeries ba = bd, aa = ad;
  std::vector<Point2> lines[4];
  for (std::size_t i = 0; i < r.t_s.size(); ++i) {
    lines[0].push_back({r.t_s[i], 1e3 * r.before_distance_m[i]});
    lines[1].push_back({r.t_s[i], 1e3 * r.after_distance_m[i]});
    lines[2].push_back({r.t_s[i], kDeg * r.before_angle_rad[i]});
    lines[3].push_back({r.t_s[i], kDeg * r.after_angle_rad[i]});
  }
  SvgSeries* series[4] = {&bd, &ad, &ba, &aa};
  for (int i = 0; i < 4; ++i) {
    series[i]->lines.push_back(Thinned(lines[i], 400));
    series[i]->draw_markers = r.t_s.size() <= 60;  // markers only where they can be told apart
  }
  XYPlotOptions o;
  o.width = 520;
  o.height = 360;
  o.include_origin = true;
  o.id = "run" + std::to_string(k) + "-distance";
  o.title = r.id + ": distance error (Eq. 8)";
  o.x_label = "time since start [s]";
  o.y_label = "distance error [mm]";
  std::string both = XYPlotSvg(o, {bd, ad});
  o.id = "run" + std::to_string(k) + "-heading";
  o.title = r.id + ": heading error (Eq. 9)";
  o.y_label = "|heading error| [deg]";
  return both + XYPlotSvg(o, {ba, aa});
}

// Histogram of the final position errors, nominal and calibrated, in bins of the noise floor's
// size when it is measured (so that "at the noise floor" is the first bins).
std::string ResidualHistogramSvg(const ReportData& data) {
  double largest = 0.0;
  for (const ReportRun& r : data.runs) {
    largest = std::max({largest, r.before.final_distance_m, r.after.final_distance_m});
  }
  if (data.runs.empty() || !(largest > 0.0)) return "";
  const int bins = 12;
  const double width_m = largest / bins * (1.0 + 1e-9);
  BarSeries before{"nominal parameters", kBeforeColour, std::vector<double>(bins, 0.0)};
  BarSeries after{"calibrated parameters", kAfterColour, std::vector<double>(bins, 0.0)};
  for (const ReportRun& r : data.runs) {
    before.values[std::min(bins - 1, static_cast<int>(r.before.final_distance_m / width_m))] += 1;
    after.values[std::min(bins - 1, static_cast<int>(r.after.final_distance_m / width_m))] += 1;
  }
  std::vector<std::string> categories;
  for (int b = 0; b < bins; ++b) categories.push_back(Fmt("%.0f", 1e3 * width_m * (b + 1)));
  BarChartOptions o;
  o.title = "Final position error of the validation runs";
  o.x_label = "final position error up to [mm]";
  if (data.noise_floor.available) {
    o.x_label += " (noise of one run: " +
                 Fmt("%.1f mm", 1e3 * std::sqrt(2.0) * data.noise_floor.noise_sigma_m) + ")";
  }
  o.y_label = "runs";
  o.width = 760;
  return BarChartSvg(o, categories, {before, after});
}

// The t_s samples of a track drawn as ReportRun holds it: the start pose and the final pose
// around them when the track is longer than t_s (MakeReportRun), else the samples alone.
std::size_t SampleOffset(const std::vector<Point2>& xy, const std::vector<double>& t_s) {
  return xy.size() >= t_s.size() + 2 ? 1 : 0;
}

// Which error of a run a distance figure shows, and how it is scaled for display.
struct ErrorQuantity {
  const char* label;  // y axis
  const char* unit;   // display unit
  double scale;       // SI or rad -> display unit
  const std::vector<double> ReportRun::*before;
  const std::vector<double> ReportRun::*after;
  const ReportErrorBand ReportErrorBands::*before_band;
  const ReportErrorBand ReportErrorBands::*after_band;
};
const ErrorQuantity kPositionError = {"position error [mm]",
                                      "mm",
                                      1e3,
                                      &ReportRun::before_distance_m,
                                      &ReportRun::after_distance_m,
                                      &ReportErrorBands::position_before,
                                      &ReportErrorBands::position_after};
const ErrorQuantity kHeadingError = {"|heading error| [deg]",
                                     "deg",
                                     kDeg,
                                     &ReportRun::before_angle_rad,
                                     &ReportRun::after_angle_rad,
                                     &ReportErrorBands::heading_before,
                                     &ReportErrorBands::heading_after};

// One panel: every run thin, and the model's band over the runs (ReportErrorBand): the median
// (thick) and the band between the quartiles.
std::string ErrorAlongDistancePanel(const ReportData& d, const ErrorQuantity& q, bool after,
                                    double y_hi, const std::string& id) {
  const char* colour = after ? kAfterColour : kBeforeColour;
  SvgSeries runs = Series("each held-out run", colour);
  runs.opacity = 0.25;
  runs.line_width = 1.0;
  // A run whose error leaves the top of the shared scale gets a marker at its peak's distance on
  // the top edge, and the legend names the largest peak: no extreme is cut off unsaid.
  SvgSeries beyond = Series("", "#000000");
  beyond.draw_lines = false;
  beyond.draw_markers = true;
  beyond.marker_radius = 4.0;
  double peak = 0.0;
  // The thin lines are the background of the band: ~6000 points a panel in all, 30 to 150 a run.
  const std::size_t per_run =
      std::clamp<std::size_t>(6000 / std::max<std::size_t>(1, d.runs.size()), 30, 150);
  for (const ReportRun& r : d.runs) {
    const std::vector<double>& e = r.*(after ? q.after : q.before);
    if (r.along_m.size() != e.size() || e.empty()) continue;
    std::vector<Point2> line;
    for (std::size_t i : ThinnedIndices(e.size(), per_run)) {
      line.push_back({r.along_m[i], q.scale * e[i]});
    }
    runs.lines.push_back(line);
    const std::size_t top =
        static_cast<std::size_t>(std::max_element(e.begin(), e.end()) - e.begin());
    if (q.scale * e[top] > y_hi) {
      beyond.lines.push_back({{r.along_m[top], 0.97 * y_hi}});
      peak = std::max(peak, q.scale * e[top]);
    }
  }
  beyond.name =
      StrFormat("beyond the top: %zu run(s), peak %.4g %s", beyond.lines.size(), peak, q.unit);
  SvgSeries band = Series("quartiles over runs", colour), median = Series("median", colour);
  band.fill = colour;
  band.opacity = 0.3;
  median.line_width = 3.0;
  const ReportErrorBand& b = d.error_bands.*(after ? q.after_band : q.before_band);
  std::vector<Point2> upper, lower, mid;
  for (std::size_t k = 0; k < b.distance_m.size(); ++k) {
    lower.push_back({b.distance_m[k], q.scale * b.lower_quartile[k]});
    mid.push_back({b.distance_m[k], q.scale * b.median[k]});
    upper.push_back({b.distance_m[k], q.scale * b.upper_quartile[k]});
  }
  band.lines.push_back(upper);
  band.lines.back().insert(band.lines.back().end(), lower.rbegin(), lower.rend());
  median.lines.push_back(mid);
  XYPlotOptions o;
  o.id = id;
  o.width = 480;
  o.height = 360;
  o.title = after ? "calibrated parameters" : "nominal parameters";
  o.x_label = "distance travelled (ground truth) [m]";
  o.y_label = q.label;
  o.include_origin = true;
  o.y_lo = 0.0;
  o.y_hi = y_hi;
  if (beyond.lines.empty()) return XYPlotSvg(o, {runs, band, median});
  return XYPlotSvg(o, {runs, band, median, beyond});
}

// Both panels of one quantity on one y range, wide enough for both bands (median and upper
// quartile never run off the top) and at least 95 % of every run's samples; a run beyond it is
// marked at the top edge (ErrorAlongDistancePanel).
std::string ErrorAlongDistanceSvgs(const ReportData& d, const ErrorQuantity& q,
                                   const std::string& id) {
  std::vector<double> all;
  for (const ReportRun& r : d.runs) {
    if (r.along_m.empty()) continue;
    for (const auto* e : {&(r.*q.before), &(r.*q.after)}) {
      for (double v : *e) all.push_back(q.scale * v);
    }
  }
  if (all.empty()) return "";
  double band_top = 0.0;
  for (const ReportErrorBand* b :
       {&(d.error_bands.*q.before_band), &(d.error_bands.*q.after_band)}) {
    for (double v : b->upper_quartile) band_top = std::max(band_top, q.scale * v);
    for (double v : b->median) band_top = std::max(band_top, q.scale * v);
  }
  const double y_hi = 1.05 * std::max({Quantile(all, 0.95), band_top, 1e-9});
  return ErrorAlongDistancePanel(d, q, false, y_hi, id + "-nominal") +
         ErrorAlongDistancePanel(d, q, true, y_hi, id + "-calibrated");
}

// Box plots of the drift of every window, one box per drift length and parameter set.
std::string DriftBoxesSvg(const ReportData& d, bool rotation) {
  std::vector<std::string> categories;
  BoxSeries before{"nominal parameters", kBeforeColour, {}};
  BoxSeries after{"calibrated parameters", kAfterColour, {}};
  for (const ReportDriftRow& r : d.drift) {
    if (r.before_translation_percent_windows.empty()) continue;
    categories.push_back(Fmt("%g m", r.length_m) + " (" + std::to_string(r.windows) + ")");
    const auto scaled = [&](const std::vector<double>& v) {
      std::vector<double> out;
      for (double x : v) out.push_back(rotation ? kDeg * x : x);
      return out;
    };
    before.samples.push_back(scaled(rotation ? r.before_rotation_rad_per_m_windows
                                             : r.before_translation_percent_windows));
    after.samples.push_back(scaled(rotation ? r.after_rotation_rad_per_m_windows
                                            : r.after_translation_percent_windows));
  }
  if (categories.empty()) return "";
  BarChartOptions o;
  o.width = 480;
  o.height = 360;
  o.title = rotation ? "Rotation drift per window" : "Translation drift per window";
  o.x_label = "window along the ground truth (windows)";
  o.y_label = rotation ? "rotation error [deg/m]" : "translation error [% of distance]";
  return BoxPlotSvg(o, categories, {before, after});
}

// One run, nominal beside calibrated: the odometry coloured by its position error on the run's
// scale (ColouredTrackScale), the ground truth grey beneath it, both panels on one range.
std::string ColouredTrackSvgs(const ReportRun& r, std::size_t k) {
  const double error_hi_m = ColouredTrackScale(r);
  const std::size_t off = SampleOffset(r.ground_truth_xy, r.t_s);
  if (r.t_s.empty() || r.ground_truth_xy.size() < r.t_s.size() + off ||
      r.before_xy.size() < r.t_s.size() + off || r.after_xy.size() < r.t_s.size() + off ||
      r.before_distance_m.size() != r.t_s.size() || r.after_distance_m.size() != r.t_s.size()) {
    return "";
  }
  const std::vector<std::size_t> keep = ThinnedIndices(r.t_s.size(), 120);
  SvgSeries gt = Series("ground truth", kGroundTruthColour);
  gt.line_width = 4.0;
  gt.lines.emplace_back();
  for (std::size_t i : keep) gt.lines[0].push_back(r.ground_truth_xy[i + off]);
  double x_lo = 0, x_hi = 0, y_lo = 0, y_hi = 0;
  bool first = true;
  for (const auto* xy : {&r.ground_truth_xy, &r.before_xy, &r.after_xy}) {
    for (const Point2& p : *xy) {
      x_lo = first ? p.x : std::min(x_lo, p.x);
      x_hi = first ? p.x : std::max(x_hi, p.x);
      y_lo = first ? p.y : std::min(y_lo, p.y);
      y_hi = first ? p.y : std::max(y_hi, p.y);
      first = false;
    }
  }
  const double pad = 0.05 * std::max({x_hi - x_lo, y_hi - y_lo, 1e-3});
  std::string out;
  for (bool after : {false, true}) {
    SvgSeries odo = Series(after ? "calibrated odometry" : "nominal odometry", "#000000");
    odo.line_width = 2.0;
    odo.value_lo = 0.0;
    odo.value_hi = error_hi_m;
    odo.lines.emplace_back();
    odo.values.emplace_back();
    const std::vector<Point2>& xy = after ? r.after_xy : r.before_xy;
    const std::vector<double>& e = after ? r.after_distance_m : r.before_distance_m;
    for (std::size_t i : keep) {
      odo.lines[0].push_back(xy[i + off]);
      odo.values[0].push_back(e[i]);
    }
    XYPlotOptions o;
    o.id = "track" + std::to_string(k) + (after ? "-calibrated" : "-nominal");
    o.width = 340;
    o.height = 360;
    o.equal_aspect = true;
    o.x_lo = x_lo - pad;
    o.x_hi = x_hi + pad;
    o.y_lo = y_lo - pad;
    o.y_hi = y_hi + pad;
    o.title = std::string(after ? "calibrated" : "nominal") + ", ATE " +
              Fmt("%.0f mm", 1e3 * (after ? r.after : r.before).rms_distance_m);
    o.x_label = "x [m]";
    o.y_label = "y [m]";
    out += XYPlotSvg(o, {gt, odo});
  }
  return out;
}

// The flower (Palacin Fig. 9-10): every validation run in its start frame.
std::string FlowerSvg(const ReportData& data) {
  SvgSeries gt = Series("ground truth", kGroundTruthColour);
  SvgSeries before = Series(kBeforeName, kBeforeColour);
  SvgSeries after = Series(kAfterName, kAfterColour);
  gt.line_width = 3.0;
  before.line_width = after.line_width = 1.2;
  before.opacity = 0.8;
  before.dash = "5 3";
  const std::size_t most = PointsPerRun(data.runs.size(), 3);
  for (const ReportRun& r : data.runs) {
    gt.lines.push_back(Thinned(r.ground_truth_xy, most));
    before.lines.push_back(Thinned(r.before_xy, most));
    after.lines.push_back(Thinned(r.after_xy, most));
  }
  XYPlotOptions o;
  o.id = "flower";
  o.title = "Validation runs in their start frame";
  o.x_label = "x in the start frame [m] (robot heading at start = +x)";
  o.y_label = "y in the start frame [m]";
  o.width = 600;
  o.height = 620;
  o.equal_aspect = true;
  return XYPlotSvg(o, {gt, before, after});
}

// Zoom on the end points: final odometry minus final ground truth, in mm.
std::string EndPointsSvg(const ReportData& data) {
  FinalErrorScatter s;
  s.before_name = kBeforeName;
  s.after_name = kAfterName;
  s.origin_name = "ground truth end point (origin)";
  s.run_opacity = 0.7;
  s.origin_opacity = 1.0;
  s.origin_marker_radius = 5.0;
  for (const ReportRun& r : data.runs) {
    s.before_m.push_back(r.before_final_error);
    s.after_m.push_back(r.after_final_error);
  }
  s.plot.id = "end-points";
  s.plot.title = "Zoom on the end points: odometry minus ground truth";
  s.plot.x_label = "final error along start-frame x [mm]";
  s.plot.y_label = "final error along start-frame y [mm]";
  s.plot.width = 600;
  s.plot.height = 620;
  return FinalErrorScatterSvg(s);
}

// Per-trajectory final errors, mean over the validation repetitions (the model's rows).
void AddFinalErrorBars(const ReportData& data, ReportFigures* f) {
  std::vector<std::string> order;
  BarSeries bd{"nominal parameters", kBeforeColour, {}},
      ad{"calibrated parameters", kAfterColour, {}};
  BarSeries ba = bd, aa = ad;
  for (const ReportSummaryRow& t : data.trajectories) {
    order.push_back(t.group);
    bd.values.push_back(1e3 * t.before.final_distance_m);
    ad.values.push_back(1e3 * t.after.final_distance_m);
    ba.values.push_back(kDeg * t.before.final_angle_rad);
    aa.values.push_back(kDeg * t.after.final_angle_rad);
  }
  BarChartOptions o;
  o.title = "Final position error per trajectory (mean over validation repetitions)";
  o.x_label = "trajectory";
  o.y_label = "final position error [mm]";
  f->final_distance_bars = BarChartSvg(o, order, {bd, ad});
  o.title = "Final heading error per trajectory (mean over validation repetitions)";
  o.y_label = "final |heading error| [deg]";
  f->final_angle_bars = BarChartSvg(o, order, {ba, aa});
}

std::string CorrelationSvg(const ReportData& data) {
  if (!data.has_correlation) return "";
  std::vector<std::string> labels;
  // A held parameter has no correlation (its row is 0): its label says why.
  for (const ReportParameter& p : data.parameters) {
    labels.push_back(p.name + (p.held ? " (held)" : ""));
  }
  return HeatMapSvg("Correlation of the fitted parameters (-1 blue, +1 red)", labels,
                    data.correlation);
}

}  // namespace

ReportFigures MakeReportFigures(const ReportData& data) {
  ReportFigures f;
  f.flower = FlowerSvg(data);
  f.end_points = EndPointsSvg(data);
  AddFinalErrorBars(data, &f);
  f.correlation = CorrelationSvg(data);
  for (std::size_t k :
       WorstRuns(data, static_cast<std::size_t>(std::max(0, data.worst_runs_drawn)))) {
    f.error_along_time.push_back(ErrorAlongTimeSvgs(data.runs[k], k));
    f.error_along_time_runs.push_back(k);
  }
  f.residual_histogram = ResidualHistogramSvg(data);
  f.position_error_along_distance = ErrorAlongDistanceSvgs(data, kPositionError, "dist-pos");
  f.heading_error_along_distance = ErrorAlongDistanceSvgs(data, kHeadingError, "dist-head");
  f.drift_translation_boxes = DriftBoxesSvg(data, false);
  f.drift_rotation_boxes = DriftBoxesSvg(data, true);
  for (std::size_t k : WorstRuns(data, kMostColouredTracks)) {
    std::string svgs = ColouredTrackSvgs(data.runs[k], k);
    if (svgs.empty()) continue;
    f.coloured_tracks.push_back(std::move(svgs));
    f.coloured_track_runs.push_back(k);
  }
  return f;
}

}  // namespace fitcal::io
