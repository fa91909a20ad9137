#include "io/report_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

namespace fitcal::io {

namespace {

constexpr double kDeg = 180.0 / M_PI;
const char* const kGroundTruthColour = "#9a9a9a";  // light grey: drawn under the odometry
const char* const kBeforeColour = "#d55e00";       // vermillion: nominal parameters
const char* const kAfterColour = "#0072b2";        // blue: calibrated parameters
const char* const kBeforeName = "odometry, nominal parameters";
const char* const kAfterName = "odometry, calibrated parameters";

std::string Fmt(const char* format, double v) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

double Improvement(double before, double after) {
  return before > 0.0 ? 100.0 * (before - after) / before : 0.0;
}

// Every % change on the page and in summary.md has one sign: 100 (after - before) / before, so
// an error that shrank is negative (and green), a parameter that grew positive. metrics.json's
// improvement_percent keeps Palacin Table 6's sign (positive = better) and says so in its name.
std::string ChangePercentText(double before, double after) {
  return Fmt("%+.1f %%", -Improvement(before, after));
}

// Table 6 columns: (label, unit, getter, is angle).
struct Column {
  const char* key;    // machine name, SI
  const char* label;  // for people
  bool is_angle;
  double ReportMetrics::*field;
};
const Column kColumns[] = {
    {"rms_distance_m", "RMS distance error [m] (Eq. 12)", false, &ReportMetrics::rms_distance_m},
    {"rms_angle", "RMS |angle| error [deg] (Eq. 13)", true, &ReportMetrics::rms_angle_rad},
    {"max_distance_m", "max distance error [m] (Eq. 10)", false, &ReportMetrics::max_distance_m},
    {"max_angle", "max |angle| error [deg] (Eq. 11)", true, &ReportMetrics::max_angle_rad},
    {"final_distance_m", "final position error [m]", false, &ReportMetrics::final_distance_m},
    {"final_angle", "final |angle| error [deg]", true, &ReportMetrics::final_angle_rad},
    {"cf", "CF (Eq. 14, m and rad)", false, &ReportMetrics::cf},
};

// Key with the unit suffix of the output: angles are degrees at the edge.
std::string KeyOf(const Column& c) { return std::string(c.key) + (c.is_angle ? "_deg" : ""); }
double ValueOf(const Column& c, const ReportMetrics& m) {
  return m.*c.field * (c.is_angle ? kDeg : 1.0);
}
const char* FormatOf(const Column& c) { return c.is_angle ? "%.3f" : "%.4f"; }

std::vector<std::string> TrajectoryOrder(const std::vector<ReportRun>& runs) {
  std::vector<std::string> order;
  for (const ReportRun& r : runs) {
    bool seen = false;
    for (const std::string& t : order) seen = seen || t == r.trajectory;
    if (!seen) order.push_back(r.trajectory);
  }
  return order;
}

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string JsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string JsonMetrics(const ReportMetrics& m) {
  std::string out = "{";
  bool first = true;
  for (const Column& c : kColumns) {
    out += (first ? "" : ", ") + JsonString(KeyOf(c)) + ": " + JsonNumber(ValueOf(c, m));
    first = false;
  }
  return out + "}";
}

std::string JsonStats(const ReportStatistics& s, double scale) {
  return "{\"rmse\": " + JsonNumber(s.rmse * scale) + ", \"mean\": " + JsonNumber(s.mean * scale) +
         ", \"median\": " + JsonNumber(s.median * scale) +
         ", \"std\": " + JsonNumber(s.std * scale) + ", \"min\": " + JsonNumber(s.min * scale) +
         ", \"max\": " + JsonNumber(s.max * scale) + "}";
}

SvgSeries Series(const std::string& name, const std::string& colour) {
  SvgSeries s;
  s.name = name;
  s.color = colour;
  return s;
}

double ParamScale(const ReportParameter& p) { return p.is_angle ? kDeg : 1.0; }

// At most `most` points of a polyline for drawing, evenly strided, first and last kept: a run
// logged at 100 Hz has far more points than a 600-pixel figure can show, and the real-data report
// must stay small (README: under 2 MB for the OptiOdom omni3 set).
std::vector<Point2> Thinned(const std::vector<Point2>& line, std::size_t most) {
  if (line.size() <= most || most < 2) return line;
  std::vector<Point2> out;
  out.reserve(most);
  const double step = static_cast<double>(line.size() - 1) / static_cast<double>(most - 1);
  for (std::size_t i = 0; i < most; ++i) {
    out.push_back(line[static_cast<std::size_t>(std::lround(step * static_cast<double>(i)))]);
  }
  return out;
}

// Points per polyline of the figure of every run: ~40,000 points in all (~0.6 MB of SVG), at
// least 40 per run so that a circle still looks round.
std::size_t PointsPerRun(std::size_t runs, std::size_t lines_per_run) {
  const std::size_t total = 40000;
  return std::max<std::size_t>(
      40, std::min<std::size_t>(400, total / std::max<std::size_t>(1, runs * lines_per_run)));
}

// The runs the error-along-time figures show: largest calibrated CF first.
std::vector<std::size_t> WorstRuns(const ReportData& data, std::size_t most) {
  std::vector<std::size_t> order(data.runs.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return data.runs[a].after.cf > data.runs[b].after.cf;
  });
  order.resize(std::min(order.size(), most));
  return order;
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

// Indices 0..n-1 thinned to at most `most`, first and last kept (as Thinned).
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

// Linear interpolation of y(x) at x0 along non-decreasing x; NaN outside [x.front(), x.back()].
double InterpolateAt(const std::vector<double>& x, const std::vector<double>& y, double x0) {
  if (x.empty() || x0 < x.front() || x0 > x.back()) return std::nan("");
  const std::size_t j = static_cast<std::size_t>(std::lower_bound(x.begin(), x.end(), x0) -
                                                 x.begin());
  if (j == 0) return y[0];
  const double span = x[j] - x[j - 1];
  const double f = span > 0.0 ? (x0 - x[j - 1]) / span : 1.0;
  return y[j - 1] + f * (y[j] - y[j - 1]);
}

double QuantileOf(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double at = q * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(at));
  const std::size_t hi = std::min(v.size() - 1, lo + 1);
  return v[lo] + (at - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

// Which error of a run a distance figure shows, and how it is scaled for display.
struct ErrorQuantity {
  const char* label;  // y axis
  double scale;       // SI or rad -> display unit
  const std::vector<double> ReportRun::*before;
  const std::vector<double> ReportRun::*after;
};
const ErrorQuantity kPositionError = {"position error [mm]", 1e3, &ReportRun::before_distance_m,
                                      &ReportRun::after_distance_m};
const ErrorQuantity kHeadingError = {"|heading error| [deg]", kDeg, &ReportRun::before_angle_rad,
                                     &ReportRun::after_angle_rad};

// One panel: every run thin, and over the runs that reach each distance the median (thick) and
// the band between the quartiles, on a grid of 80 distances up to where half the runs still go.
std::string ErrorAlongDistancePanel(const ReportData& d, const ErrorQuantity& q, bool after,
                                    double y_hi, const std::string& id) {
  const char* colour = after ? kAfterColour : kBeforeColour;
  SvgSeries runs = Series("each held-out run", colour);
  runs.opacity = 0.25;
  runs.line_width = 1.0;
  // The thin lines are the background of the band: ~6000 points a panel in all, 30 to 150 a run.
  const std::size_t per_run =
      std::clamp<std::size_t>(6000 / std::max<std::size_t>(1, d.runs.size()), 30, 150);
  std::vector<double> ends;
  for (const ReportRun& r : d.runs) {
    const std::vector<double>& e = r.*(after ? q.after : q.before);
    if (r.along_m.size() != e.size() || e.empty()) continue;
    ends.push_back(r.along_m.back());
    std::vector<Point2> line;
    for (std::size_t i : ThinnedIndices(e.size(), per_run)) {
      line.push_back({r.along_m[i], q.scale * e[i]});
    }
    runs.lines.push_back(line);
  }
  SvgSeries band = Series("quartiles over runs", colour), median = Series("median", colour);
  band.fill = colour;
  band.opacity = 0.3;
  median.line_width = 3.0;
  const double reach = QuantileOf(ends, 0.5);
  std::vector<Point2> upper, lower, mid;
  for (int k = 0; k <= 80 && reach > 0.0; ++k) {
    const double at = reach * k / 80.0;
    std::vector<double> v;
    for (const ReportRun& r : d.runs) {
      const std::vector<double>& e = r.*(after ? q.after : q.before);
      if (r.along_m.size() != e.size()) continue;
      const double y = InterpolateAt(r.along_m, e, at);
      if (std::isfinite(y)) v.push_back(q.scale * y);
    }
    if (v.empty()) continue;
    lower.push_back({at, QuantileOf(v, 0.25)});
    mid.push_back({at, QuantileOf(v, 0.5)});
    upper.push_back({at, QuantileOf(v, 0.75)});
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
  return XYPlotSvg(o, {runs, band, median});
}

// Both panels of one quantity on one y range, wide enough for the larger of the two medians'
// worst quartile and at least 95 % of every run's samples.
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
  const double y_hi = 1.05 * std::max(QuantileOf(all, 0.95), 1e-9);
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

// The held-out runs whose odometry is drawn coloured by its error: every run up to this many,
// else the worst by calibrated CF (the size budget of the page).
constexpr std::size_t kMostColouredTracks = 30;

// The colour scale of one run's pair of panels: 0 to its largest position error, nominal or
// calibrated (so the two panels compare, and a good run is not all dark beside a bad one).
double ColouredTrackScale(const ReportRun& r) {
  const double hi = std::max(r.before.max_distance_m, r.after.max_distance_m);
  double samples = 0.0;
  for (const auto* e : {&r.before_distance_m, &r.after_distance_m}) {
    for (double v : *e) samples = std::max(samples, v);
  }
  const double out = std::max(hi, samples);
  return out > 0.0 ? out : 1.0;
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

}  // namespace

bool GotWorse(const ReportRun& run) {
  return run.after.cf > run.before.cf || run.after.rms_distance_m > run.before.rms_distance_m;
}

ReportFigures MakeReportFigures(const ReportData& data) {
  ReportFigures f;
  // The flower (Palacin Fig. 9-10): every validation run in its start frame.
  {
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
    f.flower = XYPlotSvg(o, {gt, before, after});
  }
  // Zoom on the end points: final odometry minus final ground truth, in mm.
  {
    SvgSeries truth = Series("ground truth end point (origin)", "#000000");
    truth.draw_lines = false;
    truth.draw_markers = true;
    truth.marker_radius = 5.0;
    truth.lines.push_back({Point2{0.0, 0.0}});
    SvgSeries before = Series(kBeforeName, kBeforeColour);
    SvgSeries after = Series(kAfterName, kAfterColour);
    for (SvgSeries* s : {&before, &after}) {
      s->draw_lines = false;
      s->draw_markers = true;
      s->opacity = 0.7;
      s->lines.emplace_back();
    }
    for (const ReportRun& r : data.runs) {
      before.lines[0].push_back({1e3 * r.before_final_error.x, 1e3 * r.before_final_error.y});
      after.lines[0].push_back({1e3 * r.after_final_error.x, 1e3 * r.after_final_error.y});
    }
    XYPlotOptions o;
    o.id = "end-points";
    o.title = "Zoom on the end points: odometry minus ground truth";
    o.x_label = "final error along start-frame x [mm]";
    o.y_label = "final error along start-frame y [mm]";
    o.width = 600;
    o.height = 620;
    o.equal_aspect = true;
    o.include_origin = true;
    f.end_points = XYPlotSvg(o, {before, after, truth});
  }
  // Per-trajectory final errors, mean over the validation repetitions.
  {
    const std::vector<std::string> order = TrajectoryOrder(data.runs);
    BarSeries bd{"nominal parameters", kBeforeColour, {}},
        ad{"calibrated parameters", kAfterColour, {}};
    BarSeries ba = bd, aa = ad;
    for (const std::string& t : order) {
      double sbd = 0, sad = 0, sba = 0, saa = 0;
      int n = 0;
      for (const ReportRun& r : data.runs) {
        if (r.trajectory != t) continue;
        sbd += r.before.final_distance_m;
        sad += r.after.final_distance_m;
        sba += r.before.final_angle_rad;
        saa += r.after.final_angle_rad;
        ++n;
      }
      bd.values.push_back(1e3 * sbd / n);
      ad.values.push_back(1e3 * sad / n);
      ba.values.push_back(kDeg * sba / n);
      aa.values.push_back(kDeg * saa / n);
    }
    BarChartOptions o;
    o.title = "Final position error per trajectory (mean over validation repetitions)";
    o.x_label = "trajectory";
    o.y_label = "final position error [mm]";
    f.final_distance_bars = BarChartSvg(o, order, {bd, ad});
    o.title = "Final heading error per trajectory (mean over validation repetitions)";
    o.y_label = "final |heading error| [deg]";
    f.final_angle_bars = BarChartSvg(o, order, {ba, aa});
  }
  if (data.has_correlation) {
    std::vector<std::string> labels;
    // A held parameter has no correlation (its row is 0): its label says why.
    for (const ReportParameter& p : data.parameters) {
      labels.push_back(p.name + (p.held ? " (held)" : ""));
    }
    f.correlation = HeatMapSvg("Correlation of the fitted parameters (-1 blue, +1 red)", labels,
                               data.correlation);
  }
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

namespace {

const char* const kStyle =
    "*{box-sizing:border-box}\n"
    "body{font-family:sans-serif;margin:0 auto;padding:16px;max-width:1300px;color:#222;"
    "line-height:1.4}\n"
    "svg{max-width:100%;height:auto}\n"
    "figure.wide{overflow-x:auto}figure.wide svg{min-width:640px}\n"
    ".scroll{overflow-x:auto;max-width:100%}\n"
    "table{border-collapse:collapse;margin:8px 0 16px}\n"
    "th,td{border:1px solid #bbb;padding:3px 8px;text-align:right}\n"
    "th:first-child,td:first-child,td.k{text-align:left}\n"
    // Numbers never break ("4.7e-" / "14"); text cells keep a readable measure on a phone and
    // the table scrolls instead of squeezing them to one word a line.
    "td:not(:first-child):not(.k){white-space:nowrap}td.k{min-width:12em}\n"
    "th{background:#f0f0f0}\n"
    "code{overflow-wrap:anywhere}\n"
    ".warn{background:#fff3cd;border:1px solid #e0b000;padding:8px 12px;white-space:pre-wrap;"
    "font-family:monospace;overflow-x:auto}\n"
    ".ok{background:#e6f4ea;border:1px solid #5a5;padding:8px 12px}\n"
    ".banner{padding:10px 16px;border:2px solid;margin:12px 0 20px}\n"
    ".banner h2{margin:0 0 6px}\n"
    ".PASS{background:#e6f4ea;border-color:#2a7a2a}\n"
    ".WARN{background:#fff3cd;border-color:#b08000}\n"
    ".FAIL{background:#fde2e1;border-color:#b00020}\n"
    ".banner li.PASS,.banner li.WARN,.banner li.FAIL{background:none;border:none}\n"
    ".figs{display:flex;flex-wrap:wrap;gap:12px}\n"
    "figure{margin:0 0 12px;max-width:100%}figcaption{font-size:13px;color:#555;"
    "max-width:640px}\n"
    ".better{color:#060}.worse{color:#a00;font-weight:bold}\n"
    ".flag{color:#a00;background:#fde2e1;border:1px solid #b00020;padding:6px 10px}\n"
    ".held{color:#555;font-style:italic}ul.key{font-size:16px}\n"
    "pre{white-space:pre-wrap;font-size:13px}\n"
    // A phone (a 390 px screen): figures keep their drawn size, so that their 11-15 px text
    // stays readable, and scroll sideways in their box instead of shrinking to a third.
    "@media (max-width:700px){body{padding:8px}svg{max-width:none}"
    ".figs,figure{overflow-x:auto;max-width:100%}.figs>svg{flex-shrink:0}"
    "figure.wide svg{min-width:0}}\n"
    ".figs.flagged{border-left:4px solid #b00020;padding-left:6px}\n";

// A table inside a horizontally scrolling box: wide tables scroll on a phone instead of pushing
// the page wider than the screen.
void OpenTable(std::ostringstream& h, const std::string& id = "") {
  h << "<div class=\"scroll\"" << (id.empty() ? "" : " id=\"" + id + "\"") << ">\n<table>\n";
}
void CloseTable(std::ostringstream& h) { h << "</table>\n</div>\n"; }

void HtmlVerdict(std::ostringstream& h, const ReportData& d) {
  h << "<div class=\"banner " << EscapeXml(d.verdict)
    << "\" id=\"verdict\">\n<h2>Verdict: " << EscapeXml(d.verdict) << "</h2>\n<ul>\n";
  for (const ReportVerdictReason& r : d.verdict_reasons) {
    h << "<li class=\"" << EscapeXml(r.level) << "\"><b>" << EscapeXml(r.level) << "</b> "
      << EscapeXml(r.check) << ": " << EscapeXml(r.message) << " (<a href=\"#"
      << EscapeXml(r.section) << "\">" << EscapeXml(r.section) << "</a>)</li>\n";
  }
  h << "</ul>\n</div>\n";
}

// The numbers an engineer looks for first, in one line each: ATE, drift, the runs that got worse.
void HtmlKeyNumbers(std::ostringstream& h, const ReportData& d) {
  if (d.summary.empty()) return;
  const ReportSummaryRow& all = d.summary.back();
  int worse = 0;
  for (const ReportRun& r : d.runs) worse += GotWorse(r) ? 1 : 0;
  h << "<ul class=\"key\" id=\"key\">\n<li>ATE RMSE (mean over " << all.runs
    << " held-out runs, no alignment): <b>" << Fmt("%.1f", 1e3 * all.before.rms_distance_m)
    << " &rarr; " << Fmt("%.1f mm", 1e3 * all.after.rms_distance_m) << "</b> ("
    << ChangePercentText(all.before.rms_distance_m, all.after.rms_distance_m) << ")</li>\n";
  for (const ReportDriftRow& r : d.drift) {
    h << "<li>drift over " << Fmt("%g m", r.length_m) << ": <b>"
      << Fmt("%.2f", r.before_translation_percent) << " &rarr; "
      << Fmt("%.2f %%", r.after_translation_percent) << "</b>, "
      << Fmt("%.3f", kDeg * r.before_rotation_rad_per_m) << " &rarr; "
      << Fmt("%.3f deg/m", kDeg * r.after_rotation_rad_per_m) << "</li>\n";
  }
  h << "<li" << (worse > 0 ? " class=\"worse\"" : "") << ">held-out runs that got worse: "
    << worse << " of " << d.runs.size() << (worse > 0 ? " (<a href=\"#worse\">list</a>)" : "")
    << "</li>\n</ul>\n";
}

void HtmlHeader(std::ostringstream& h, const ReportData& d) {
  h << "<p>Robot <b>" << EscapeXml(d.robot_name) << "</b>, data set <code>" << EscapeXml(d.dataset)
    << "</code>, calibration <code>" << EscapeXml(d.calibration) << "</code>, fitcal "
    << EscapeXml(d.tool_version) << ".<br>"
    << "Validation: " << d.runs.size() << " runs (repetitions "
    << EscapeXml(d.validation_repetitions)
    << ") that the calibration did not train on; training: " << EscapeXml(d.training_source)
    << ".<br>"
    << "Odometry sub-sampled at the ground-truth times by <b>" << EscapeXml(d.sampling)
    << "</b> time" << (d.sampling == "nearest" ? " (as Palacin et al. 2022)" : " interpolation")
    << ". Before = nominal parameters, after = calibrated parameters"
    << (d.effects.empty() ? "" : " with the calibration's effects (see Effects)") << ".</p>\n";
}

void HtmlSummaryRows(std::ostringstream& h, const ReportSummaryRow& row) {
  for (int part = 0; part < 3; ++part) {
    h << "<tr>";
    if (part == 0) {
      h << "<td rowspan=\"3\"><b>" << EscapeXml(row.group) << "</b></td><td rowspan=\"3\">"
        << row.runs << "</td>";
    }
    h << "<td class=\"k\">"
      << (part == 0   ? "before"
          : part == 1 ? "after"
                      : "change")
      << "</td>";
    for (const Column& c : kColumns) {
      const double b = ValueOf(c, row.before), a = ValueOf(c, row.after);
      if (part == 2) {
        h << "<td class=\"" << (a <= b ? "better" : "worse") << "\">" << ChangePercentText(b, a)
          << "</td>";
      } else {
        h << "<td>" << Fmt(FormatOf(c), part == 0 ? b : a) << "</td>";
      }
    }
    h << "</tr>\n";
  }
}

void HtmlSummary(std::ostringstream& h, const ReportData& d) {
  h << "<h2 id=\"summary\">Summary (Palacin Table 6)</h2>\n<p>Averages over the validation runs; "
       "change = 100 (after &minus; before) / before: negative (green) is a smaller error, as "
       "in every table of this page. The RMS distance error is the ATE RMSE.</p>\n";
  OpenTable(h);
  h << "<tr><th>group</th><th>runs</th><th></th>";
  for (const Column& c : kColumns) h << "<th>" << EscapeXml(c.label) << "</th>";
  h << "</tr>\n";
  for (const ReportSummaryRow& row : d.summary) HtmlSummaryRows(h, row);
  CloseTable(h);
}

// One row per trajectory: where a calibration that helps overall makes one path worse.
void HtmlTrajectoryGroups(std::ostringstream& h, const ReportData& d) {
  h << "<h2 id=\"groups\">Per trajectory</h2>\n<p>Mean over each trajectory's validation runs; "
       "a red value is worse with the calibration than with the nominal.</p>\n";
  OpenTable(h);
  h << "<tr><th>trajectory</th><th>runs</th><th>CF before</th><th>CF after</th>"
       "<th>final position error before [mm]</th><th>after [mm]</th>"
       "<th>final |heading error| before [deg]</th><th>after [deg]</th></tr>\n";
  for (const ReportSummaryRow& row : d.trajectories) {
    const auto cell = [&](double before, double after, const char* format, double scale) {
      h << "<td>" << Fmt(format, before * scale) << "</td><td"
        << (after > before ? " class=\"worse\"" : "") << ">" << Fmt(format, after * scale)
        << "</td>";
    };
    h << "<tr><td>" << EscapeXml(row.group) << "</td><td>" << row.runs << "</td>";
    cell(row.before.cf, row.after.cf, "%.4f", 1.0);
    cell(row.before.final_distance_m, row.after.final_distance_m, "%.1f", 1e3);
    cell(row.before.final_angle_rad, row.after.final_angle_rad, "%.3f", kDeg);
    h << "</tr>\n";
  }
  CloseTable(h);
}

// Mean signed final error (bias) in the start frame: what a constant offset of the odometry
// looks like, which the absolute errors hide.
struct Bias {
  double x_m = 0.0, y_m = 0.0, heading_rad = 0.0;
};
Bias MeanFinalError(const ReportData& d, bool after) {
  Bias b;
  for (const ReportRun& r : d.runs) {
    const Point2& e = after ? r.after_final_error : r.before_final_error;
    b.x_m += e.x;
    b.y_m += e.y;
    b.heading_rad += after ? r.after_final_heading_rad : r.before_final_heading_rad;
  }
  const double n = std::max<double>(1.0, static_cast<double>(d.runs.size()));
  return {b.x_m / n, b.y_m / n, b.heading_rad / n};
}

void HtmlDrift(std::ostringstream& h, const ReportData& d) {
  h << "<h2 id=\"drift\">Drift per distance and bias</h2>\n<p>Relative pose error over windows of "
       "the given ground-truth path length (KITTI's odometry metric; evo_rpe with a delta in "
       "metres): translation error in % of the distance, rotation error in deg per metre, mean "
       "over every window of every validation run.</p>\n";
  OpenTable(h);
  h << "<tr><th>path length [m]</th><th>windows</th><th>translation before [%]</th>"
       "<th>after [%]</th><th>rotation before [deg/m]</th><th>after [deg/m]</th>"
       "<th>windows worse after</th></tr>\n";
  for (const ReportDriftRow& r : d.drift) {
    const bool worse = r.after_translation_percent > r.before_translation_percent;
    const bool rot_worse = r.after_rotation_rad_per_m > r.before_rotation_rad_per_m;
    h << "<tr><td>" << Fmt("%g", r.length_m) << "</td><td>" << r.windows << "</td><td>"
      << Fmt("%.2f", r.before_translation_percent) << "</td><td"
      << (worse ? " class=\"worse\"" : "") << ">" << Fmt("%.2f", r.after_translation_percent)
      << "</td><td>" << Fmt("%.3f", kDeg * r.before_rotation_rad_per_m) << "</td><td"
      << (rot_worse ? " class=\"worse\"" : "") << ">"
      << Fmt("%.3f", kDeg * r.after_rotation_rad_per_m) << "</td><td"
      << (r.windows_worse > 0 ? " class=\"worse\"" : "") << ">" << r.windows_worse << " of "
      << r.windows << "</td></tr>\n";
  }
  CloseTable(h);
  h << "<p>A window is worse when its translation error is larger with the calibrated "
       "parameters than with the nominal (the windows are chosen on the ground truth, so each "
       "is the same stretch of road before and after).</p>\n";
  h << "<p>Signed mean final error (bias) over the validation runs, in each run's start "
       "frame:</p>\n";
  OpenTable(h);
  h << "<tr><th></th><th>x [mm]</th><th>y [mm]</th><th>heading [deg]</th></tr>\n";
  for (bool after : {false, true}) {
    const Bias b = MeanFinalError(d, after);
    h << "<tr><td>" << (after ? "after" : "before") << "</td><td>" << Fmt("%+.1f", 1e3 * b.x_m)
      << "</td><td>" << Fmt("%+.1f", 1e3 * b.y_m) << "</td><td>"
      << Fmt("%+.3f", kDeg * b.heading_rad) << "</td></tr>\n";
  }
  CloseTable(h);
}

void HtmlFigures(std::ostringstream& h, const ReportData& d, const ReportFigures& f) {
  h << "<h2 id=\"trajectories\">Trajectories</h2>\n<div class=\"figs\">\n<figure>" << f.flower
    << "<figcaption>Each validation run drawn from its own start pose (origin, heading +x). "
       "Grey: ground truth; dashed vermillion: odometry with the nominal parameters; blue: "
       "odometry with the calibrated parameters (compare Palacin Fig. 9-10).</figcaption>"
       "</figure>\n<figure>"
    << f.end_points
    << "<figcaption>The end of every validation run, magnified: where the odometry ended "
       "relative to the ground truth (origin). A tight blue cluster at the origin is a good "
       "calibration.</figcaption></figure>\n</div>\n";
  // The bar charts are wide: on a phone they keep readable labels and scroll sideways instead of
  // shrinking to a third.
  h << "<h2>Final error per trajectory</h2>\n<figure class=\"wide\">" << f.final_distance_bars
    << "</figure>\n<figure class=\"wide\">" << f.final_angle_bars << "</figure>\n";
  h << "<h2 id=\"errors\">Error along time: the " << f.error_along_time.size() << " worst of "
    << d.runs.size()
    << " runs</h2>\n<p>The validation runs with the largest calibrated CF (Eq. 14), worst first: "
       "the odometry at each ground-truth time (Eq. 8 and 9). Every run is in the per-run table "
       "and in metrics.csv.</p>\n";
  for (const std::string& svgs : f.error_along_time) {
    h << "<div class=\"figs\">\n" << svgs << "</div>\n";
  }
}

void HtmlDistanceFigures(std::ostringstream& h, const ReportFigures& f) {
  if (f.position_error_along_distance.empty() && f.drift_translation_boxes.empty()) return;
  h << "<h2 id=\"distance\">Error against distance travelled</h2>\n<p>Every held-out run "
       "(thin), the median over the runs (thick) and the band between their quartiles, against "
       "the distance the ground truth travelled; the odometry starts at the ground truth's "
       "start pose, nothing else is aligned. Nominal left, calibrated right, on one scale. The "
       "median and band stop where half the runs have ended.</p>\n";
  for (const std::string* svgs : {&f.position_error_along_distance,
                                  &f.heading_error_along_distance}) {
    if (!svgs->empty()) h << "<div class=\"figs\">\n" << *svgs << "</div>\n";
  }
  if (f.drift_translation_boxes.empty()) return;
  h << "<p>Drift of every window of each length along the ground truth (the table above is "
       "their mean): box from the first to the third quartile, the median across it, whiskers "
       "to 1.5 interquartile ranges, dots beyond. The number of windows is in brackets.</p>\n"
    << "<div class=\"figs\">\n" << f.drift_translation_boxes << f.drift_rotation_boxes
    << "</div>\n";
}

// The held-out runs that got worse with the calibration (GotWorse), flagged by name.
void HtmlWorseRuns(std::ostringstream& h, const ReportData& d) {
  std::vector<const ReportRun*> worse;
  for (const ReportRun& r : d.runs) {
    if (GotWorse(r)) worse.push_back(&r);
  }
  h << "<h2 id=\"worse\">Held-out runs that got worse</h2>\n";
  if (worse.empty()) {
    h << "<p class=\"ok\">None: every one of the " << d.runs.size()
      << " held-out runs has a lower CF (Eq. 14) and a lower ATE RMSE with the calibrated "
         "parameters.</p>\n";
    return;
  }
  h << "<p class=\"flag\"><b>" << worse.size() << " of " << d.runs.size()
    << " held-out runs got worse</b> with the calibration: their CF (Eq. 14) or their ATE RMSE "
       "(RMS position error, Eq. 12) rose.</p>\n";
  OpenTable(h);
  h << "<tr><th>run</th><th>CF before</th><th>CF after</th><th>ATE RMSE before [mm]</th>"
       "<th>after [mm]</th></tr>\n";
  for (const ReportRun* r : worse) {
    const auto cell = [&](double before, double after, const char* format, double scale) {
      h << "<td>" << Fmt(format, scale * before) << "</td><td"
        << (after > before ? " class=\"worse\"" : "") << ">" << Fmt(format, scale * after)
        << "</td>";
    };
    h << "<tr><td>" << EscapeXml(r->id) << "</td>";
    cell(r->before.cf, r->after.cf, "%.4f", 1.0);
    cell(r->before.rms_distance_m, r->after.rms_distance_m, "%.1f", 1e3);
    h << "</tr>\n";
  }
  CloseTable(h);
}

void HtmlColouredTracks(std::ostringstream& h, const ReportData& d, const ReportFigures& f) {
  if (f.coloured_tracks.empty()) return;
  h << "<h2 id=\"tracks\">Held-out runs coloured by their error</h2>\n<p>"
    << (f.coloured_tracks.size() == d.runs.size()
            ? std::string("Every held-out run")
            : "The " + std::to_string(f.coloured_tracks.size()) + " held-out runs (of " +
                  std::to_string(d.runs.size()) + ") with the largest calibrated CF")
    << ", worst calibrated CF first, in its start frame: the odometry coloured by its position "
       "error at each ground-truth time, the ground truth grey beneath it; nominal left, "
       "calibrated right. Each run has its own scale, from 0 to its largest error (nominal or "
       "calibrated, given beside its name):</p>\n<figure>"
    << ColourBarSvg("position error, fraction of the run's largest", 0.0, 1.0) << "</figure>\n";
  for (std::size_t i = 0; i < f.coloured_tracks.size(); ++i) {
    const ReportRun& r = d.runs[f.coloured_track_runs[i]];
    const bool worse = GotWorse(r);
    h << "<h3" << (worse ? " class=\"worse\"" : "") << ">" << EscapeXml(r.id) << " (scale 0-"
      << Fmt("%.0f mm", 1e3 * ColouredTrackScale(r)) << ")" << (worse ? ": got worse" : "")
      << "</h3>\n<div class=\"figs" << (worse ? " flagged" : "") << "\">\n"
      << f.coloured_tracks[i] << "</div>\n";
  }
}

void HtmlResiduals(std::ostringstream& h, const ReportData& d, const ReportFigures& f) {
  h << "<h2 id=\"residuals\">Residual against the noise floor</h2>\n<p>";
  const ReportNoiseFloor& n = d.noise_floor;
  if (n.available) {
    h << "Noise floor: the scatter of the calibrated final position errors between repetitions "
         "of one trajectory, "
      << Fmt("%.1f mm", 1e3 * n.noise_sigma_m)
      << " per axis. Systematic part (each run's trajectory mean): "
      << Fmt("%.1f mm", 1e3 * n.systematic_rms_m) << " RMS; F = " << Fmt("%.2f", n.f_statistic)
      << ", p = " << Fmt("%.2g", n.p_value)
      << ". A significant systematic part larger than the noise means the model lacks an effect "
         "(<code>fitcal diagnose</code>).";
  } else {
    h << "No trajectory has two validation runs: the repetition noise is not measured.";
  }
  h << "</p>\n";
  if (!f.residual_histogram.empty()) {
    h << "<figure class=\"wide\">" << f.residual_histogram << "</figure>\n";
  }
}

void HtmlStatistics(std::ostringstream& h, const ReportData& d) {
  h << "<h2 id=\"statistics\">Statistics over validation runs (named as evo)</h2>\n";
  OpenTable(h);
  h << "<tr><th>metric</th><th></th><th>rmse</th><th>mean</th><th>median</th><th>std</th>"
       "<th>min</th><th>max</th></tr>\n";
  for (const ReportStatisticsRow& s : d.statistics) {
    const double scale = s.is_angle ? kDeg : 1.0;
    const char* fmt = s.is_angle ? "%.3f" : "%.4f";
    for (int part = 0; part < 2; ++part) {
      const ReportStatistics& v = part == 0 ? s.before : s.after;
      h << "<tr>";
      if (part == 0) {
        h << "<td rowspan=\"2\">" << EscapeXml(s.metric) << (s.is_angle ? " [deg]" : "") << "</td>";
      }
      h << "<td class=\"k\">" << (part == 0 ? "before" : "after") << "</td>";
      for (double x : {v.rmse, v.mean, v.median, v.std, v.min, v.max}) {
        h << "<td>" << Fmt(fmt, x * scale) << "</td>";
      }
      h << "</tr>\n";
    }
  }
  CloseTable(h);
}

// Lengths change by percent, angles by degrees (a percentage of an angle means nothing).
std::string ChangeText(const ReportParameter& p) {
  if (p.is_angle) return Fmt("%+.3f deg", (p.calibrated - p.nominal) * kDeg);
  return Fmt("%+.2f %%", p.nominal != 0.0 ? 100.0 * (p.calibrated - p.nominal) / p.nominal : 0.0);
}

void HtmlParameters(std::ostringstream& h, const ReportData& d) {
  h << "<h2 id=\"parameters\">Parameters</h2>\n<p>" << EscapeXml(d.uncertainty_note) << "</p>\n";
  OpenTable(h);
  h << "<tr><th>parameter</th><th>unit</th><th>nominal</th><th>calibrated</th>"
       "<th>&plusmn;1 sigma</th><th>change</th><th>status</th>"
    << (d.has_cv ? "<th>CV mean</th><th>CV std</th><th>CV min</th><th>CV max</th>" : "")
    << "</tr>\n";
  for (const ReportParameter& p : d.parameters) {
    const double s = ParamScale(p);
    const char* fmt = p.is_angle ? "%.4f" : "%.6f";
    h << "<tr><td>" << EscapeXml(p.name) << "</td><td>" << EscapeXml(p.unit) << "</td><td>"
      << Fmt(fmt, p.nominal * s) << "</td><td>" << Fmt(fmt, p.calibrated * s) << "</td><td>"
      << (p.has_sigma ? Fmt("%.2g", p.sigma * s) : "-") << "</td><td>"
      << (p.held ? "-" : ChangeText(p)) << "</td><td"
      << (p.held       ? " class=\"held\">held at nominal"
          : p.at_bound ? " class=\"worse\">AT BOUND"
                       : ">fitted")
      << "</td>";
    if (d.has_cv) {
      h << "<td>" << Fmt(fmt, p.cv_mean * s) << "</td><td>" << Fmt("%.2g", p.cv_std * s)
        << "</td><td>" << Fmt(fmt, p.cv_min * s) << "</td><td>" << Fmt(fmt, p.cv_max * s)
        << "</td>";
    }
    h << "</tr>\n";
  }
  CloseTable(h);
}

void HtmlEffects(std::ostringstream& h, const ReportData& d) {
  if (d.effects.empty()) return;
  h << "<h2 id=\"effects\">Effects</h2>\n<p>Effects the calibration carries beyond the model's "
       "parameters (<code>fitcal diagnose</code>), with the one-sigma the YAML records, and the "
       "held-out CF (Eq. 14, all validation runs) of the model with and without them.</p>\n";
  OpenTable(h);
  h << "<tr><th></th><th>nominal</th><th>calibrated parameters alone</th>"
       "<th>parameters + effects</th></tr>\n<tr><td>held-out CF</td><td>"
    << Fmt("%.4f", d.summary.back().before.cf) << "</td><td>" << Fmt("%.4f", d.cf_parameters_only)
    << "</td><td>" << Fmt("%.4f", d.summary.back().after.cf) << "</td></tr>\n";
  CloseTable(h);
  OpenTable(h);
  h << "<tr><th>effect</th><th>parameter</th><th>value</th><th>&plusmn;1 sigma</th></tr>\n";
  for (const ReportEffect& e : d.effects) {
    for (std::size_t k = 0; k < e.values.size(); ++k) {
      h << "<tr><td>" << EscapeXml(e.name) << "</td><td class=\"k\">"
        << EscapeXml(e.parameter_names[k]) << "</td><td>" << Fmt("%.6g", e.values[k]) << "</td><td>"
        << Fmt("%.2g", e.sigmas[k]) << "</td></tr>\n";
    }
  }
  CloseTable(h);
}

void HtmlIdentifiability(std::ostringstream& h, const ReportData& d) {
  h << "<h2 id=\"identifiability\">Identifiability</h2>\n";
  if (!d.identifiability_checked) {
    h << "<p>Not analysed: the calibration's training runs are not in this data set.</p>\n";
  } else if (d.identifiable) {
    h << "<p class=\"ok\">The training runs determine every parameter"
      << (d.condition_number > 0.0 ? " (condition number " + Fmt("%.3g", d.condition_number) +
                                         " in relative units; no parameter pair correlated "
                                         "beyond 0.99)"
                                   : "")
      << ".</p>\n";
  } else {
    h << "<div class=\"warn\">";
    for (const std::string& line : d.identifiability_lines) h << EscapeXml(line) << "\n";
    h << "</div>\n";
  }
}

void HtmlCrossValidation(std::ostringstream& h, const ReportData& d) {
  if (!d.has_cv) return;
  h << "<h2>Leave-one-repetition-out cross-validation</h2>\n<p>Each fold fits on all "
       "repetitions but one and validates on the one left out. Validation CF (calibrated): mean "
    << Fmt("%.4f", d.cv_cf_after.mean) << ", std " << Fmt("%.4f", d.cv_cf_after.std) << ", min "
    << Fmt("%.4f", d.cv_cf_after.min) << ", max " << Fmt("%.4f", d.cv_cf_after.max)
    << " (nominal: mean " << Fmt("%.4f", d.cv_cf_before.mean)
    << "). The parameter spread across folds is in the parameter table; the folds share all but "
       "one repetition, so that spread understates the uncertainty of one fit (a jackknife "
       "estimate multiplies the CV std by sqrt(folds - 1)).</p>\n";
  OpenTable(h);
  h << "<tr><th>held-out repetition</th><th>converged</th><th>training CF</th>"
       "<th>validation CF before</th><th>validation CF after</th></tr>\n";
  for (const ReportFold& fold : d.folds) {
    h << "<tr><td>" << fold.held_out_repetition << "</td><td>" << (fold.usable ? "yes" : "NO")
      << "</td><td>" << Fmt("%.4f", fold.cf_training) << "</td><td>"
      << Fmt("%.4f", fold.cf_validation_before) << "</td><td>"
      << Fmt("%.4f", fold.cf_validation_after) << "</td></tr>\n";
  }
  CloseTable(h);
}

void HtmlPerRun(std::ostringstream& h, const ReportData& d) {
  h << "<h2>Per-run metrics</h2>\n<details><summary>" << d.runs.size()
    << " validation runs (also in metrics.csv)</summary>\n";
  OpenTable(h);
  h << "<tr><th>run</th><th>path length [m]</th>";
  for (const Column& c : kColumns) h << "<th>" << EscapeXml(c.label) << "<br>before / after</th>";
  h << "</tr>\n";
  for (const ReportRun& r : d.runs) {
    h << "<tr><td>" << EscapeXml(r.id) << "</td><td>" << Fmt("%.2f", r.path_length_m) << "</td>";
    for (const Column& c : kColumns) {
      h << "<td>" << Fmt(FormatOf(c), ValueOf(c, r.before)) << " / "
        << Fmt(FormatOf(c), ValueOf(c, r.after)) << "</td>";
    }
    h << "</tr>\n";
  }
  CloseTable(h);
  h << "</details>\n";
}

// Several calibrations side by side on the same validation runs.
void HtmlComparison(std::ostringstream& h, const ReportData& d) {
  if (d.comparison.empty()) return;
  h << "<h2 id=\"comparison\">Calibrations compared</h2>\n<p>Every calibration on the same "
       "validation runs (those none of them trained on); the rest of the page reports the first. "
       "Below, the held-out CF per trajectory of calibration #1, #2, ... in the order above, the "
       "lowest in bold.</p>\n";
  OpenTable(h);
  h << "<tr><th>calibration</th><th>verdict</th><th>training</th><th>held-out CF</th>"
       "<th>final position error [mm]</th><th>final |heading error| [deg]</th>"
       "<th>drift [% of distance]</th></tr>\n";
  h << "<tr><td>nominal</td><td></td><td></td><td>" << Fmt("%.4f", d.comparison[0].all.before.cf)
    << "</td><td>" << Fmt("%.1f", 1e3 * d.comparison[0].all.before.final_distance_m) << "</td><td>"
    << Fmt("%.3f", kDeg * d.comparison[0].all.before.final_angle_rad) << "</td><td>"
    << Fmt("%.2f", d.comparison[0].drift.before_translation_percent) << "</td></tr>\n";
  for (const ReportComparisonRow& c : d.comparison) {
    h << "<tr><td><code>" << EscapeXml(c.calibration) << "</code></td><td class=\""
      << EscapeXml(c.verdict) << "\">" << EscapeXml(c.verdict) << "</td><td class=\"k\">"
      << EscapeXml(c.training_source) << "</td><td>" << Fmt("%.4f", c.all.after.cf) << "</td><td>"
      << Fmt("%.1f", 1e3 * c.all.after.final_distance_m) << "</td><td>"
      << Fmt("%.3f", kDeg * c.all.after.final_angle_rad) << "</td><td>"
      << Fmt("%.2f", c.drift.after_translation_percent) << "</td></tr>\n";
  }
  CloseTable(h);
  OpenTable(h);
  h << "<tr><th>trajectory</th><th>runs</th><th>CF nominal</th>";
  for (std::size_t k = 0; k < d.comparison.size(); ++k) h << "<th>CF #" << k + 1 << "</th>";
  h << "</tr>\n";
  for (std::size_t t = 0; t < d.trajectories.size(); ++t) {
    h << "<tr><td>" << EscapeXml(d.trajectories[t].group) << "</td><td>" << d.trajectories[t].runs
      << "</td><td>" << Fmt("%.4f", d.trajectories[t].before.cf) << "</td>";
    double best = d.trajectories[t].before.cf;
    for (const ReportComparisonRow& c : d.comparison)
      best = std::min(best, c.trajectory_cf_after[t]);
    for (const ReportComparisonRow& c : d.comparison) {
      const double v = c.trajectory_cf_after[t];
      h << "<td>" << (v == best ? "<b>" : "") << Fmt("%.4f", v) << (v == best ? "</b>" : "")
        << "</td>";
    }
    h << "</tr>\n";
  }
  CloseTable(h);
}

}  // namespace

std::string ReportHtml(const ReportData& d) {
  const ReportFigures f = MakeReportFigures(d);
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
    << "<title>fitcal validation report: " << EscapeXml(d.verdict) << "</title>\n<style>\n"
    << kStyle << "</style>\n</head>\n<body>\n<h1>fitcal validation report</h1>\n";
  HtmlVerdict(h, d);
  HtmlKeyNumbers(h, d);
  HtmlHeader(h, d);
  HtmlComparison(h, d);
  HtmlSummary(h, d);
  HtmlTrajectoryGroups(h, d);
  HtmlWorseRuns(h, d);
  HtmlDrift(h, d);
  HtmlDistanceFigures(h, f);
  HtmlColouredTracks(h, d, f);
  HtmlFigures(h, d, f);
  HtmlResiduals(h, d, f);
  HtmlStatistics(h, d);
  h << "<h2 id=\"calibration\">Calibration</h2>\n<p>" << EscapeXml(d.calibration_note) << "</p>\n";
  HtmlParameters(h, d);
  if (!f.correlation.empty()) h << "<figure>" << f.correlation << "</figure>\n";
  HtmlEffects(h, d);
  HtmlIdentifiability(h, d);
  HtmlCrossValidation(h, d);
  HtmlPerRun(h, d);
  h << "</body>\n</html>\n";
  return h.str();
}

namespace {

// A GitHub-flavoured Markdown table cell: '|' escaped (a bare one splits the cell, as the
// "|angle|" labels did), line breaks as spaces.
std::string MdCell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') {
      out += "\\|";
    } else if (c == '\n') {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out;
}

// "| a | b |" from cells (escaped).
std::string MdRow(const std::vector<std::string>& cells) {
  std::string out = "|";
  for (const std::string& c : cells) out += " " + MdCell(c) + " |";
  return out + "\n";
}

// The separator row: the first `left` columns left-aligned, the rest right-aligned.
std::string MdRule(std::size_t columns, std::size_t left) {
  std::string out = "|";
  for (std::size_t i = 0; i < columns; ++i) out += i < left ? "---|" : "---:|";
  return out + "\n";
}

void MdVerdict(std::ostringstream& m, const ReportData& d) {
  m << "## Verdict: " << d.verdict << "\n\n";
  for (const ReportVerdictReason& r : d.verdict_reasons) {
    m << "- **" << r.level << "** " << r.check << ": " << r.message << "\n";
  }
  m << "\n";
  if (d.summary.empty()) return;
  // The key numbers of the page (HtmlKeyNumbers), in the same words.
  const ReportSummaryRow& all = d.summary.back();
  m << "- ATE RMSE (mean over " << all.runs << " held-out runs, no alignment): "
    << Fmt("%.1f", 1e3 * all.before.rms_distance_m) << " -> "
    << Fmt("%.1f mm", 1e3 * all.after.rms_distance_m) << " ("
    << ChangePercentText(all.before.rms_distance_m, all.after.rms_distance_m) << ")\n";
  std::string worse;
  int n = 0;
  for (const ReportRun& r : d.runs) {
    if (!GotWorse(r)) continue;
    worse += (n++ ? ", " : "") + r.id;
  }
  m << "- held-out runs that got worse: " << n << " of " << d.runs.size()
    << (n > 0 ? " (" + worse + ")" : "") << "\n\n";
}

void MdSummary(std::ostringstream& m, const ReportData& d) {
  m << "## Summary (Palacin Table 6)\n\nchange = 100 (after - before) / before: negative is a "
       "smaller error, as in every table here.\n\n";
  std::vector<std::string> header = {"group", "runs", ""};
  for (const Column& c : kColumns) header.push_back(c.label);
  m << MdRow(header) << MdRule(header.size(), 3);
  for (const ReportSummaryRow& row : d.summary) {
    for (int part = 0; part < 3; ++part) {
      std::vector<std::string> cells = {part == 0 ? row.group : "",
                                        part == 0 ? std::to_string(row.runs) : "",
                                        part == 0   ? "before"
                                        : part == 1 ? "after"
                                                    : "change"};
      for (const Column& c : kColumns) {
        const double b = ValueOf(c, row.before), a = ValueOf(c, row.after);
        cells.push_back(part == 2 ? ChangePercentText(b, a)
                                  : Fmt(FormatOf(c), part == 0 ? b : a));
      }
      m << MdRow(cells);
    }
  }
  m << "\n## Per trajectory\n\n";
  const std::vector<std::string> per = {
      "trajectory", "runs", "CF before", "CF after", "final position before [mm]", "after [mm]"};
  m << MdRow(per) << MdRule(per.size(), 1);
  for (const ReportSummaryRow& row : d.trajectories) {
    m << MdRow({row.group, std::to_string(row.runs), Fmt("%.4f", row.before.cf),
                Fmt("%.4f", row.after.cf), Fmt("%.1f", 1e3 * row.before.final_distance_m),
                Fmt("%.1f", 1e3 * row.after.final_distance_m) +
                    (row.after.final_distance_m > row.before.final_distance_m ? " (worse)" : "")});
  }
}

void MdDrift(std::ostringstream& m, const ReportData& d) {
  m << "\n## Drift per distance (relative pose error) and bias\n\n";
  const std::vector<std::string> header = {"path length [m]",         "windows",
                                           "translation before [%]",  "after [%]",
                                           "rotation before [deg/m]", "after [deg/m]"};
  m << MdRow(header) << MdRule(header.size(), 0);
  for (const ReportDriftRow& r : d.drift) {
    m << MdRow({Fmt("%g", r.length_m), std::to_string(r.windows),
                Fmt("%.2f", r.before_translation_percent), Fmt("%.2f", r.after_translation_percent),
                Fmt("%.3f", kDeg * r.before_rotation_rad_per_m),
                Fmt("%.3f", kDeg * r.after_rotation_rad_per_m)});
  }
  m << "\n";
  const std::vector<std::string> bias = {"signed mean final error", "x [mm]", "y [mm]",
                                         "heading [deg]"};
  m << MdRow(bias) << MdRule(bias.size(), 1);
  for (bool after : {false, true}) {
    const Bias b = MeanFinalError(d, after);
    m << MdRow({after ? "after" : "before", Fmt("%+.1f", 1e3 * b.x_m), Fmt("%+.1f", 1e3 * b.y_m),
                Fmt("%+.3f", kDeg * b.heading_rad)});
  }
}

void MdStatistics(std::ostringstream& m, const ReportData& d) {
  m << "\n## Statistics over validation runs (evo names)\n\n";
  const std::vector<std::string> header = {"metric", "",    "rmse", "mean",
                                           "median", "std", "min",  "max"};
  m << MdRow(header) << MdRule(header.size(), 2);
  for (const ReportStatisticsRow& s : d.statistics) {
    const double scale = s.is_angle ? kDeg : 1.0;
    for (int part = 0; part < 2; ++part) {
      const ReportStatistics& v = part == 0 ? s.before : s.after;
      std::vector<std::string> cells = {part == 0 ? s.metric + (s.is_angle ? " [deg]" : "") : "",
                                        part == 0 ? "before" : "after"};
      for (double x : {v.rmse, v.mean, v.median, v.std, v.min, v.max}) {
        cells.push_back(Fmt(s.is_angle ? "%.3f" : "%.4f", x * scale));
      }
      m << MdRow(cells);
    }
  }
}

void MdParameters(std::ostringstream& m, const ReportData& d) {
  m << "\n## Parameters\n\n" << d.uncertainty_note << "\n\n";
  std::vector<std::string> header = {"parameter", "unit",   "nominal", "calibrated",
                                     "+-1 sigma", "change", "status"};
  if (d.has_cv) header.insert(header.end(), {"CV std", "CV min", "CV max"});
  m << MdRow(header) << MdRule(header.size(), 2);
  for (const ReportParameter& p : d.parameters) {
    const double s = ParamScale(p);
    const char* fmt = p.is_angle ? "%.4f" : "%.6f";
    std::vector<std::string> cells = {p.name,
                                      p.unit,
                                      Fmt(fmt, p.nominal * s),
                                      Fmt(fmt, p.calibrated * s),
                                      p.has_sigma ? Fmt("%.2g", p.sigma * s) : "-",
                                      p.held ? "-" : ChangeText(p),
                                      p.held       ? "held at nominal"
                                      : p.at_bound ? "AT BOUND"
                                                   : "fitted"};
    if (d.has_cv) {
      cells.insert(cells.end(),
                   {Fmt("%.2g", p.cv_std * s), Fmt(fmt, p.cv_min * s), Fmt(fmt, p.cv_max * s)});
    }
    m << MdRow(cells);
  }
  if (d.effects.empty()) return;
  m << "\n## Effects\n\n";
  const std::vector<std::string> header_cf = {"", "nominal", "calibrated parameters alone",
                                              "parameters + effects"};
  m << MdRow(header_cf) << MdRule(header_cf.size(), 1)
    << MdRow({"held-out CF", Fmt("%.4f", d.summary.back().before.cf),
              Fmt("%.4f", d.cf_parameters_only), Fmt("%.4f", d.summary.back().after.cf)})
    << "\n";
  const std::vector<std::string> header_e = {"effect", "parameter", "value", "+-1 sigma"};
  m << MdRow(header_e) << MdRule(header_e.size(), 2);
  for (const ReportEffect& e : d.effects) {
    for (std::size_t k = 0; k < e.values.size(); ++k) {
      m << MdRow(
          {e.name, e.parameter_names[k], Fmt("%.6g", e.values[k]), Fmt("%.2g", e.sigmas[k])});
    }
  }
}

void MdComparison(std::ostringstream& m, const ReportData& d) {
  if (d.comparison.empty()) return;
  m << "## Calibrations compared (same validation runs)\n\n";
  const std::vector<std::string> header = {"calibration", "verdict", "held-out CF",
                                           "final position error [mm]",
                                           "final |heading error| [deg]"};
  m << MdRow(header) << MdRule(header.size(), 2);
  const ReportSummaryRow& nominal = d.comparison[0].all;
  m << MdRow({"nominal", "", Fmt("%.4f", nominal.before.cf),
              Fmt("%.1f", 1e3 * nominal.before.final_distance_m),
              Fmt("%.3f", kDeg * nominal.before.final_angle_rad)});
  for (const ReportComparisonRow& c : d.comparison) {
    m << MdRow({c.calibration, c.verdict, Fmt("%.4f", c.all.after.cf),
                Fmt("%.1f", 1e3 * c.all.after.final_distance_m),
                Fmt("%.3f", kDeg * c.all.after.final_angle_rad)});
  }
  m << "\n";
}

}  // namespace

std::string ReportMarkdown(const ReportData& d) {
  std::ostringstream m;
  m << "# fitcal validation report\n\n";
  MdVerdict(m, d);
  m << "- robot: " << d.robot_name << "\n- data set: `" << d.dataset << "`\n- calibration: `"
    << d.calibration << "` (" << d.calibration_note << ")\n- fitcal " << d.tool_version
    << "\n- validation: " << d.runs.size() << " runs (repetitions " << d.validation_repetitions
    << "); training: " << d.training_source << "\n- odometry sampled at the "
    << "ground-truth times by " << d.sampling << " time\n\n";
  MdComparison(m, d);
  MdSummary(m, d);
  MdDrift(m, d);
  MdStatistics(m, d);
  MdParameters(m, d);
  m << "\n## Identifiability\n\n";
  if (!d.identifiability_checked) {
    m << "Not analysed: the calibration's training runs are not in this data set.\n";
  } else if (d.identifiable) {
    m << "The training runs determine every parameter"
      << (d.condition_number > 0.0 ? " (condition number " + Fmt("%.3g", d.condition_number) + ")"
                                   : "")
      << ".\n";
  } else {
    m << "```\n";
    for (const std::string& line : d.identifiability_lines) m << line << "\n";
    m << "```\n";
  }
  if (d.has_cv) {
    m << "\n## Leave-one-repetition-out cross-validation\n\nValidation CF (calibrated) over "
      << d.folds.size() << " folds: mean " << Fmt("%.4f", d.cv_cf_after.mean) << ", std "
      << Fmt("%.4f", d.cv_cf_after.std) << ", min " << Fmt("%.4f", d.cv_cf_after.min) << ", max "
      << Fmt("%.4f", d.cv_cf_after.max) << "; nominal mean " << Fmt("%.4f", d.cv_cf_before.mean)
      << ".\n";
  }
  return m.str();
}

std::string MetricsCsv(const ReportData& d) {
  std::ostringstream c;
  c << "run,trajectory,repetition";
  for (const char* when : {"before", "after"}) {
    for (const Column& col : kColumns) c << "," << when << "_" << KeyOf(col);
  }
  // Signed final errors in the start frame (the bias of the summary) and the path length.
  c << ",path_length_m,before_final_x_m,before_final_y_m,before_final_heading_deg,"
       "after_final_x_m,after_final_y_m,after_final_heading_deg\n";
  for (const ReportRun& r : d.runs) {
    c << r.id << "," << r.trajectory << "," << r.repetition;
    for (const ReportMetrics* m : {&r.before, &r.after}) {
      for (const Column& col : kColumns) c << "," << JsonNumber(ValueOf(col, *m));
    }
    c << "," << JsonNumber(r.path_length_m);
    for (bool after : {false, true}) {
      const Point2& e = after ? r.after_final_error : r.before_final_error;
      c << "," << JsonNumber(e.x) << "," << JsonNumber(e.y) << ","
        << JsonNumber(kDeg * (after ? r.after_final_heading_rad : r.before_final_heading_rad));
    }
    c << "\n";
  }
  return c.str();
}

namespace {

// {"level": "WARN", "reasons": [{"level", "check", "section", "message"}, ...]}
std::string JsonVerdict(const ReportData& d) {
  std::string out = "{\"level\": " + JsonString(d.verdict) + ", \"reasons\": [";
  for (std::size_t i = 0; i < d.verdict_reasons.size(); ++i) {
    const ReportVerdictReason& r = d.verdict_reasons[i];
    out += std::string(i ? "," : "") + "\n    {\"level\": " + JsonString(r.level) +
           ", \"check\": " + JsonString(r.check) + ", \"section\": " + JsonString(r.section) +
           ", \"message\": " + JsonString(r.message) + "}";
  }
  return out + "]}";
}

// {"cf_parameters_only": x, "list": [{"name", "parameters": [{"name", "value", "sigma"}]}]}
std::string JsonEffects(const ReportData& d) {
  std::string out = "{\"cf_parameters_only\": " +
                    (d.effects.empty() ? std::string("null") : JsonNumber(d.cf_parameters_only)) +
                    ", \"list\": [";
  for (std::size_t i = 0; i < d.effects.size(); ++i) {
    const ReportEffect& e = d.effects[i];
    out += std::string(i ? ", " : "") + "{\"name\": " + JsonString(e.name) + ", \"parameters\": [";
    for (std::size_t k = 0; k < e.values.size(); ++k) {
      out += std::string(k ? ", " : "") + "{\"name\": " + JsonString(e.parameter_names[k]) +
             ", \"value\": " + JsonNumber(e.values[k]) + ", \"sigma\": " + JsonNumber(e.sigmas[k]) +
             "}";
    }
    out += "]}";
  }
  return out + "]}";
}

std::string JsonTrajectories(const ReportData& d) {
  std::string out = "[";
  for (std::size_t i = 0; i < d.trajectories.size(); ++i) {
    const ReportSummaryRow& row = d.trajectories[i];
    out += std::string(i ? "," : "") + "\n    {\"trajectory\": " + JsonString(row.group) +
           ", \"runs\": " + std::to_string(row.runs) + ", \"before\": " + JsonMetrics(row.before) +
           ", \"after\": " + JsonMetrics(row.after) + "}";
  }
  return out + "]";
}

std::string JsonBeforeAfter(double before, double after) {
  return "{\"before\": " + JsonNumber(before) + ", \"after\": " + JsonNumber(after) + "}";
}

int WorseCount(const ReportData& d) {
  int n = 0;
  for (const ReportRun& r : d.runs) n += GotWorse(r) ? 1 : 0;
  return n;
}

std::string JsonDrift(const ReportData& d) {
  std::string out = "[";
  for (std::size_t i = 0; i < d.drift.size(); ++i) {
    const ReportDriftRow& r = d.drift[i];
    out += std::string(i ? ", " : "") + "{\"length_m\": " + JsonNumber(r.length_m) +
           ", \"windows\": " + std::to_string(r.windows) +
           ", \"translation_percent\": {\"before\": " + JsonNumber(r.before_translation_percent) +
           ", \"after\": " + JsonNumber(r.after_translation_percent) +
           "}, \"rotation_deg_per_m\": {\"before\": " +
           JsonNumber(kDeg * r.before_rotation_rad_per_m) +
           ", \"after\": " + JsonNumber(kDeg * r.after_rotation_rad_per_m) +
           "}, \"windows_worse\": " + std::to_string(r.windows_worse) + "}";
  }
  return out + "]";
}

std::string JsonBias(const ReportData& d) {
  std::string out = "{";
  for (bool after : {false, true}) {
    const Bias b = MeanFinalError(d, after);
    out += std::string(after ? ", \"after\": " : "\"before\": ") +
           "{\"x_m\": " + JsonNumber(b.x_m) + ", \"y_m\": " + JsonNumber(b.y_m) +
           ", \"heading_deg\": " + JsonNumber(kDeg * b.heading_rad) + "}";
  }
  return out + "}";
}

std::string JsonNoiseFloor(const ReportData& d) {
  const ReportNoiseFloor& n = d.noise_floor;
  if (!n.available) return "null";
  return "{\"sigma_per_axis_m\": " + JsonNumber(n.noise_sigma_m) +
         ", \"systematic_rms_m\": " + JsonNumber(n.systematic_rms_m) +
         ", \"f_statistic\": " + JsonNumber(n.f_statistic) +
         ", \"p_value\": " + JsonNumber(n.p_value) + "}";
}

std::string JsonComparison(const ReportData& d) {
  std::string out = "[";
  for (std::size_t i = 0; i < d.comparison.size(); ++i) {
    const ReportComparisonRow& c = d.comparison[i];
    out += std::string(i ? "," : "") + "\n    {\"calibration\": " + JsonString(c.calibration) +
           ", \"verdict\": " + JsonString(c.verdict) +
           ", \"training_source\": " + JsonString(c.training_source) +
           ", \"before\": " + JsonMetrics(c.all.before) +
           ", \"after\": " + JsonMetrics(c.all.after) + ", \"per_trajectory_cf_after\": [";
    for (std::size_t t = 0; t < c.trajectory_cf_after.size(); ++t) {
      out += std::string(t ? ", " : "") + JsonNumber(c.trajectory_cf_after[t]);
    }
    out += "]}";
  }
  return out + "]";
}

}  // namespace

std::string PageStyleSheet() { return kStyle; }
std::string JsonStringOf(const std::string& text) { return JsonString(text); }
std::string JsonNumberOf(double value) { return JsonNumber(value); }

std::string MetricsJson(const ReportData& d) {
  std::ostringstream j;
  const ReportSummaryRow* all = d.summary.empty() ? nullptr : &d.summary.back();
  j << "{\n  \"version\": " << kMetricsJsonVersion << ",\n  \"kind\": \"report\""
    << ",\n  \"tool_version\": " << JsonString(d.tool_version)
    << ",\n  \"dataset\": " << JsonString(d.dataset)
    << ",\n  \"calibration\": " << JsonString(d.calibration)
    << ",\n  \"robot\": " << JsonString(d.robot_name)
    << ",\n  \"odometry_sampling\": " << JsonString(d.sampling)
    << ",\n  \"verdict\": " << JsonVerdict(d)
    << ",\n  \"training_source\": " << JsonString(d.training_source)
    << ",\n  \"effects\": " << JsonEffects(d) << ",\n  \"per_trajectory\": " << JsonTrajectories(d)
    << ",\n  \"held_out_runs\": " << d.runs.size()
    << ",\n  \"held_out_runs_worse\": " << WorseCount(d)
    << ",\n  \"ate_rmse_m\": "
    << (all ? JsonBeforeAfter(all->before.rms_distance_m, all->after.rms_distance_m) : "null")
    << ",\n  \"cf\": " << (all ? JsonBeforeAfter(all->before.cf, all->after.cf) : "null")
    << ",\n  \"drift\": " << JsonDrift(d) << ",\n  \"comparison\": " << JsonComparison(d)
    << ",\n  \"bias\": " << JsonBias(d) << ",\n  \"noise_floor\": " << JsonNoiseFloor(d)
    << ",\n  \"training_repetitions\": " << JsonString(d.training_repetitions)
    << ",\n  \"validation_repetitions\": " << JsonString(d.validation_repetitions)
    << ",\n  \"summary\": [";
  for (std::size_t i = 0; i < d.summary.size(); ++i) {
    const ReportSummaryRow& row = d.summary[i];
    j << (i ? "," : "") << "\n    {\"group\": " << JsonString(row.group)
      << ", \"runs\": " << row.runs << ",\n     \"before\": " << JsonMetrics(row.before)
      << ",\n     \"after\": " << JsonMetrics(row.after) << ",\n     \"improvement_percent\": {";
    bool first = true;
    for (const Column& c : kColumns) {
      j << (first ? "" : ", ") << JsonString(KeyOf(c)) << ": "
        << JsonNumber(Improvement(ValueOf(c, row.before), ValueOf(c, row.after)));
      first = false;
    }
    j << "}}";
  }
  j << "\n  ],\n  \"statistics\": {";
  for (std::size_t i = 0; i < d.statistics.size(); ++i) {
    const ReportStatisticsRow& s = d.statistics[i];
    const double scale = s.is_angle ? kDeg : 1.0;
    j << (i ? "," : "") << "\n    " << JsonString(s.metric + (s.is_angle ? "_deg" : ""))
      << ": {\"before\": " << JsonStats(s.before, scale)
      << ", \"after\": " << JsonStats(s.after, scale) << "}";
  }
  j << "\n  },\n  \"parameters\": [";
  for (std::size_t i = 0; i < d.parameters.size(); ++i) {
    const ReportParameter& p = d.parameters[i];
    const double s = ParamScale(p);
    const std::string u = p.is_angle ? "_deg" : "_m";
    j << (i ? "," : "") << "\n    {\"name\": " << JsonString(p.name) << ", \"nominal" << u
      << "\": " << JsonNumber(p.nominal * s) << ", \"calibrated" << u
      << "\": " << JsonNumber(p.calibrated * s) << ", \"sigma" << u
      << "\": " << (p.has_sigma ? JsonNumber(p.sigma * s) : "null")
      << ", \"at_bound\": " << (p.at_bound ? "true" : "false")
      << ", \"unit\": " << JsonString(p.unit) << ", \"value\": " << JsonNumber(p.calibrated * s)
      << ", \"sigma\": " << (p.has_sigma ? JsonNumber(p.sigma * s) : "null")
      << ", \"held\": " << (p.held ? "true" : "false");
    if (p.has_cv) {
      j << ", \"cv_std" << u << "\": " << JsonNumber(p.cv_std * s) << ", \"cv_min" << u
        << "\": " << JsonNumber(p.cv_min * s) << ", \"cv_max" << u
        << "\": " << JsonNumber(p.cv_max * s);
    }
    j << "}";
  }
  j << "\n  ],\n  \"correlation\": ";
  if (d.has_correlation) {
    j << "[";
    for (std::size_t r = 0; r < d.correlation.size(); ++r) {
      j << (r ? ", " : "") << "[";
      for (std::size_t c = 0; c < d.correlation[r].size(); ++c) {
        j << (c ? ", " : "") << JsonNumber(d.correlation[r][c]);
      }
      j << "]";
    }
    j << "]";
  } else {
    j << "null";
  }
  j << ",\n  \"identifiability\": {\"checked\": " << (d.identifiability_checked ? "true" : "false")
    << ", \"identifiable\": " << (d.identifiable ? "true" : "false")
    << ", \"condition_number\": " << JsonNumber(d.condition_number) << ", \"warnings\": [";
  for (std::size_t i = 0; i < d.identifiability_lines.size(); ++i) {
    j << (i ? ", " : "") << JsonString(d.identifiability_lines[i]);
  }
  j << "]}";
  if (d.has_cv) {
    j << ",\n  \"cross_validation\": {\"cf_validation_after\": " << JsonStats(d.cv_cf_after, 1.0)
      << ", \"cf_validation_before\": " << JsonStats(d.cv_cf_before, 1.0) << ", \"folds\": [";
    for (std::size_t i = 0; i < d.folds.size(); ++i) {
      const ReportFold& f = d.folds[i];
      j << (i ? ", " : "") << "{\"held_out_repetition\": " << f.held_out_repetition
        << ", \"usable\": " << (f.usable ? "true" : "false")
        << ", \"cf_training\": " << JsonNumber(f.cf_training)
        << ", \"cf_validation_before\": " << JsonNumber(f.cf_validation_before)
        << ", \"cf_validation_after\": " << JsonNumber(f.cf_validation_after) << "}";
    }
    j << "]}";
  }
  j << ",\n  \"runs\": [";
  for (std::size_t i = 0; i < d.runs.size(); ++i) {
    const ReportRun& r = d.runs[i];
    j << (i ? "," : "") << "\n    {\"run\": " << JsonString(r.id)
      << ", \"trajectory\": " << JsonString(r.trajectory) << ", \"repetition\": " << r.repetition
      << ", \"before\": " << JsonMetrics(r.before) << ", \"after\": " << JsonMetrics(r.after)
      << ", \"ate_rmse_m\": " << JsonBeforeAfter(r.before.rms_distance_m, r.after.rms_distance_m)
      << ", \"got_worse\": " << (GotWorse(r) ? "true" : "false") << "}";
  }
  j << "\n  ]\n}\n";
  return j.str();
}

}  // namespace fitcal::io
