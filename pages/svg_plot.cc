#include "pages/svg_plot.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <iterator>
#include <sstream>
#include <utility>

#include "odometry/text_format.h"

namespace fitcal::io {

namespace {

std::string Num(double v) { return StrFormat("%.2f", v); }

std::string TickLabel(double v, double step) {
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  return StrFormat("%.*f", std::min(decimals, 6), std::abs(v) < 1e-12 ? 0.0 : v);
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool Valid() const { return lo <= hi; }
  void Pad(double fraction) {
    if (!Valid()) {
      lo = 0.0;
      hi = 1.0;
    }
    double span = hi - lo;
    if (span <= 0.0) span = std::max(std::abs(lo), 1.0) * 0.1;
    lo -= fraction * span;
    hi += fraction * span;
  }
};

void Text(std::ostringstream& out, double x, double y, const std::string& text,
          const char* anchor = "middle", int size = 12, const char* extra = "") {
  out << "<text x=\"" << Num(x) << "\" y=\"" << Num(y) << "\" font-size=\"" << size
      << "\" text-anchor=\"" << anchor << "\"" << extra << ">" << EscapeXml(text) << "</text>\n";
}

void Open(std::ostringstream& out, int width, int height, const std::string& title) {
  out << "<svg viewBox=\"0 0 " << width << " " << height << "\" width=\"" << width << "\" height=\""
      << height << "\" role=\"img\" font-family=\"sans-serif\" style=\"background:#fff\">\n<title>"
      << EscapeXml(title) << "</title>\n";
}

// A colour-blind-safe sequential scale (viridis stops) at u in [0, 1], clamped: dark blue for
// small values, yellow for large ones.
std::string SequentialColour(double u) {
  // Viridis at u = 0, 0.25, 0.5, 0.75, 1 (matplotlib), linearly between.
  static const double kStops[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  u = std::clamp(std::isfinite(u) ? u : 0.0, 0.0, 1.0);
  const int k = std::min(3, static_cast<int>(u * 4.0));
  const double f = u * 4.0 - k;
  const auto c = [&](int i) {
    return static_cast<int>(std::lround(kStops[k][i] + f * (kStops[k + 1][i] - kStops[k][i])));
  };
  return StrFormat("#%02x%02x%02x", c(0), c(1), c(2));
}

// Number of colours of an error-coloured line: pieces of one colour are one polyline, so the
// file grows with the colour changes, not with the points.
constexpr int kColourSteps = 10;

// A line in pieces, each coloured by the value at its end point (SequentialColour scale).
template <typename Px, typename Py>
void ColouredLine(std::ostringstream& out, const std::vector<Point2>& line,
                  const std::vector<double>& values, const SvgSeries& s, const Px& px,
                  const Py& py) {
  const auto step_of = [&](double v) {
    const double u = (v - s.value_lo) / (s.value_hi - s.value_lo);
    return std::clamp(static_cast<int>(std::floor((std::isfinite(u) ? u : 0.0) * kColourSteps)), 0,
                      kColourSteps - 1);
  };
  std::size_t i = 0;
  while (i + 1 < line.size()) {
    const int step = step_of(values[i + 1]);
    std::size_t j = i + 1;
    while (j + 1 < line.size() && step_of(values[j + 1]) == step) ++j;
    out << "<polyline fill=\"none\" stroke=\"" << SequentialColour((step + 0.5) / kColourSteps)
        << "\" stroke-width=\"" << s.line_width << "\" stroke-linejoin=\"round\" points=\"";
    for (std::size_t k = i; k <= j; ++k)
      out << Num(px(line[k].x)) << "," << Num(py(line[k].y)) << " ";
    out << "\"/>";
    i = j;
  }
}

}  // namespace

double TextWidthPx(const std::string& text, double font_px) {
  std::size_t chars = 0;
  for (char c : text) chars += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
  return 0.6 * font_px * static_cast<double>(chars);
}

std::string ColourBarSvg(const std::string& label, double lo, double hi, int width) {
  const double left = 40, right = 40, bar_h = 14, top = 22;
  const double w = width - left - right;
  std::ostringstream out;
  Open(out, width, 56, label);
  Text(out, width / 2.0, 14, label, "middle", 12);
  for (int i = 0; i < kColourSteps; ++i) {
    out << "<rect x=\"" << Num(left + w * i / kColourSteps) << "\" y=\"" << Num(top)
        << "\" width=\"" << Num(w / kColourSteps + 0.5) << "\" height=\"" << Num(bar_h)
        << "\" fill=\"" << SequentialColour((i + 0.5) / kColourSteps) << "\"/>";
  }
  const double step = (hi - lo) / 4.0;
  for (int i = 0; i <= 4; ++i) {
    Text(out, left + w * i / 4.0, top + bar_h + 14, TickLabel(lo + i * step, step), "middle", 11);
  }
  out << "</svg>\n";
  return out.str();
}

std::string EscapeXml(const std::string& text) {
  static const std::pair<char, const char*> kEntities[] = {
      {'&', "&amp;"}, {'<', "&lt;"}, {'>', "&gt;"}, {'"', "&quot;"}, {'\'', "&#39;"}};
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    const auto* entity = std::find_if(std::begin(kEntities), std::end(kEntities),
                                      [c](const auto& e) { return e.first == c; });
    if (entity == std::end(kEntities)) {
      out += c;
    } else {
      out += entity->second;
    }
  }
  return out;
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double at = q * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(at));
  const std::size_t hi = std::min(v.size() - 1, lo + 1);
  return v[lo] + (at - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

std::vector<double> NiceTicks(double lo, double hi, int max_ticks) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || max_ticks < 2) return ticks;
  const double raw = (hi - lo) / (max_ticks - 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw) break;
  }
  // Multiples of the step, computed (not accumulated) so that rounding cannot drift.
  for (double i = std::ceil(lo / step - 1e-9); i * step <= hi + 1e-9 * step; i += 1.0) {
    ticks.push_back(i == 0.0 ? 0.0 : i * step);
  }
  return ticks;
}

namespace {

// Where an x-y plot draws: the plot area in pixels, the data ranges it shows, and how many
// legend entries fit a row.
struct XYFrame {
  double left = 70, right = 20, top = 34, bottom = 50;
  double pw = 0.0, ph = 0.0;  // plot area
  Range xr, yr;
  std::size_t per_row = 1;  // legend entries per row
  double px(double x) const { return left + (x - xr.lo) / (xr.hi - xr.lo) * pw; }
  double py(double y) const { return top + ph - (y - yr.lo) / (yr.hi - yr.lo) * ph; }
};

XYFrame XYFrameOf(const XYPlotOptions& o, const std::vector<SvgSeries>& series) {
  XYFrame f;
  for (const SvgSeries& s : series) {
    for (const auto& line : s.lines) {
      for (const Point2& p : line) {
        f.xr.Add(p.x);
        f.yr.Add(p.y);
      }
    }
  }
  if (o.include_origin) {
    f.xr.Add(0.0);
    f.yr.Add(0.0);
  }
  f.xr.Pad(0.05);
  f.yr.Pad(0.05);
  if (o.x_lo < o.x_hi) f.xr = Range{o.x_lo, o.x_hi};
  if (o.y_lo < o.y_hi) f.yr = Range{o.y_lo, o.y_hi};
  f.pw = o.width - f.left - f.right;
  // Legend below the plot: as many entries per row as their longest name allows.
  std::size_t longest = 1;
  for (const SvgSeries& s : series) longest = std::max(longest, s.name.size());
  f.per_row = std::max<std::size_t>(
      1, static_cast<std::size_t>(f.pw / (40.0 + 6.5 * static_cast<double>(longest))));
  const double legend_h = 22.0 * static_cast<double>((series.size() + f.per_row - 1) / f.per_row);
  f.ph = o.height - f.top - f.bottom - legend_h;
  if (o.equal_aspect) {
    // Widen the smaller span so one unit has the same length on both axes.
    const double scale = std::max((f.xr.hi - f.xr.lo) / f.pw, (f.yr.hi - f.yr.lo) / f.ph);
    const double xc = 0.5 * (f.xr.lo + f.xr.hi), yc = 0.5 * (f.yr.lo + f.yr.hi);
    f.xr = Range{xc - 0.5 * scale * f.pw, xc + 0.5 * scale * f.pw};
    f.yr = Range{yc - 0.5 * scale * f.ph, yc + 0.5 * scale * f.ph};
  }
  return f;
}

// A grid line across the plot (from x = left, pw wide) and its label at each y tick of `yt`.
template <typename ToPixelY>
void YGrid(std::ostringstream& out, double left, double pw, const std::vector<double>& yt,
           const ToPixelY& py) {
  const double ystep = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  for (double t : yt) {
    out << "<line x1=\"" << Num(left) << "\" y1=\"" << Num(py(t)) << "\" x2=\"" << Num(left + pw)
        << "\" y2=\"" << Num(py(t)) << "\" stroke=\"#e4e4e4\"/>\n";
    Text(out, left - 6, py(t) + 4, TickLabel(t, ystep), "end", 11);
  }
}

// Title, frame, grid, tick labels and axis labels.
void XYAxes(std::ostringstream& out, const XYPlotOptions& o, const XYFrame& f) {
  const double left = f.left, top = f.top, pw = f.pw, ph = f.ph;
  const auto px = [&](double x) { return f.px(x); };
  const auto py = [&](double y) { return f.py(y); };
  Text(out, o.width / 2.0, 20, o.title, "middle", 15, " font-weight=\"bold\"");
  out << "<rect x=\"" << Num(left) << "\" y=\"" << Num(top) << "\" width=\"" << Num(pw)
      << "\" height=\"" << Num(ph) << "\" fill=\"none\" stroke=\"#333\"/>\n";
  const auto xt = NiceTicks(f.xr.lo, f.xr.hi, std::max(3, static_cast<int>(pw / 80)));
  const auto yt = NiceTicks(f.yr.lo, f.yr.hi, std::max(3, static_cast<int>(ph / 50)));
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1.0;
  for (double t : xt) {
    out << "<line x1=\"" << Num(px(t)) << "\" y1=\"" << Num(top) << "\" x2=\"" << Num(px(t))
        << "\" y2=\"" << Num(top + ph) << "\" stroke=\"#e4e4e4\"/>\n";
    Text(out, px(t), top + ph + 16, TickLabel(t, xstep), "middle", 11);
  }
  YGrid(out, left, pw, yt, py);
  Text(out, left + pw / 2, top + ph + 36, o.x_label, "middle", 13);
  const double ylx = 18, yly = top + ph / 2;
  Text(out, ylx, yly, o.y_label, "middle", 13,
       (" transform=\"rotate(-90 " + Num(ylx) + " " + Num(yly) + ")\"").c_str());
}

// One series inside the plot area: filled polygons, lines (plain or coloured by value), markers.
void XYSeries(std::ostringstream& out, const SvgSeries& s, const XYFrame& f) {
  const auto px = [&](double x) { return f.px(x); };
  const auto py = [&](double y) { return f.py(y); };
  out << "<g opacity=\"" << s.opacity << "\">";
  for (std::size_t li = 0; li < s.lines.size(); ++li) {
    const std::vector<Point2>& line = s.lines[li];
    if (!s.fill.empty()) {
      out << "<polygon fill=\"" << s.fill << "\" stroke=\"none\" points=\"";
      for (const Point2& p : line) out << Num(px(p.x)) << "," << Num(py(p.y)) << " ";
      out << "\"/>";
      continue;
    }
    if (li < s.values.size() && s.values[li].size() == line.size()) {
      ColouredLine(out, line, s.values[li], s, px, py);
    } else if (s.draw_lines && line.size() > 1) {
      out << "<polyline fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\"" << s.line_width
          << "\"";
      if (!s.dash.empty()) out << " stroke-dasharray=\"" << s.dash << "\"";
      out << " points=\"";
      for (const Point2& p : line) out << Num(px(p.x)) << "," << Num(py(p.y)) << " ";
      out << "\"/>";
    }
    if (s.draw_markers) {
      for (const Point2& p : line) {
        out << "<circle cx=\"" << Num(px(p.x)) << "\" cy=\"" << Num(py(p.y)) << "\" r=\""
            << s.marker_radius << "\" fill=\"" << s.color << "\"/>";
      }
    }
  }
  out << "</g>\n";
}

// The legend below the plot, per_row entries a row.
void XYLegend(std::ostringstream& out, const std::vector<SvgSeries>& series, const XYFrame& f) {
  const double ly0 = f.top + f.ph + 56;
  for (std::size_t i = 0; i < series.size(); ++i) {
    const double lx =
        f.left + static_cast<double>(i % f.per_row) * (f.pw / static_cast<double>(f.per_row));
    const double ly = ly0 + 22.0 * static_cast<double>(i / f.per_row);
    const SvgSeries& s = series[i];
    if (!s.fill.empty()) {
      out << "<rect x=\"" << Num(lx) << "\" y=\"" << Num(ly - 10)
          << "\" width=\"24\" height=\"12\" "
          << "fill=\"" << s.fill << "\" opacity=\"" << s.opacity << "\"/>";
    } else if (s.draw_lines) {
      const std::string colour = s.values.empty() ? s.color : SequentialColour(0.5);
      out << "<line x1=\"" << Num(lx) << "\" y1=\"" << Num(ly - 4) << "\" x2=\"" << Num(lx + 24)
          << "\" y2=\"" << Num(ly - 4) << "\" stroke=\"" << colour << "\" stroke-width=\"2.5\"";
      if (!s.dash.empty()) out << " stroke-dasharray=\"" << s.dash << "\"";
      out << "/>";
    }
    if (s.draw_markers) {
      out << "<circle cx=\"" << Num(lx + 12) << "\" cy=\"" << Num(ly - 4) << "\" r=\"4\" fill=\""
          << s.color << "\"/>";
    }
    Text(out, lx + 30, ly, s.name, "start", 12);
  }
}

}  // namespace

std::string XYPlotSvg(const XYPlotOptions& o, const std::vector<SvgSeries>& series) {
  const XYFrame f = XYFrameOf(o, series);
  std::ostringstream out;
  Open(out, o.width, o.height, o.title);
  XYAxes(out, o, f);
  // Ids must be unique in a document that embeds several plots.
  static std::atomic<int> next_clip_id{0};
  const std::string clip_id =
      "clip-" + (o.id.empty() ? std::to_string(next_clip_id++) : EscapeXml(o.id));
  out << "<clipPath id=\"" << clip_id << "\"><rect x=\"" << Num(f.left) << "\" y=\"" << Num(f.top)
      << "\" width=\"" << Num(f.pw) << "\" height=\"" << Num(f.ph) << "\"/></clipPath>\n";
  out << "<g clip-path=\"url(#" << clip_id << ")\">\n";
  for (const SvgSeries& s : series) XYSeries(out, s, f);
  out << "</g>\n";
  XYLegend(out, series, f);
  out << "</svg>\n";
  return out.str();
}

namespace {

// How the category labels under a bar or box chart are written: level when every label fits its
// group, else turned upright (reading upwards, ending under the group's centre), the figure
// taller by the longest label.
struct CategoryLabels {
  bool slanted = false;
  double extra_height = 0.0;
};
constexpr double kCategoryFontPx = 11.0;

CategoryLabels LayOutCategoryLabels(const std::vector<std::string>& categories, double group_w) {
  double widest = 0.0;
  for (const std::string& c : categories)
    widest = std::max(widest, TextWidthPx(c, kCategoryFontPx));
  CategoryLabels out;
  // Level labels need a gap of one character between neighbours; upright ones only one line
  // height per group, and take their length in height.
  out.slanted = widest + 0.6 * kCategoryFontPx > group_w;
  if (out.slanted) out.extra_height = widest;
  return out;
}

void CategoryLabel(std::ostringstream& out, const CategoryLabels& labels, double cx, double axis_y,
                   const std::string& text) {
  if (!labels.slanted) {
    Text(out, cx, axis_y + 15, text, "middle", static_cast<int>(kCategoryFontPx));
    return;
  }
  const double x = cx + 0.35 * kCategoryFontPx, y = axis_y + 6;  // glyphs centred on cx
  Text(out, x, y, text, "end", static_cast<int>(kCategoryFontPx),
       (" transform=\"rotate(-90 " + Num(x) + " " + Num(y) + ")\"").c_str());
}

// Axis titles and the legend (one row of swatches) under a chart whose category labels take
// `extra` pixels more than a level row.
void AxisLabelsAndLegend(std::ostringstream& out, double left, double top, double pw, double ph,
                         double extra, const BarChartOptions& o,
                         const std::vector<BarSeries>& series) {
  Text(out, left + pw / 2, top + ph + 36 + extra, o.x_label, "middle", 13);
  const double ylx = 18, yly = top + ph / 2;
  Text(out, ylx, yly, o.y_label, "middle", 13,
       (" transform=\"rotate(-90 " + Num(ylx) + " " + Num(yly) + ")\"").c_str());
  double lx = left;
  for (const BarSeries& s : series) {
    const double ly = top + ph + 60 + extra;
    out << "<rect x=\"" << Num(lx) << "\" y=\"" << Num(ly - 11)
        << "\" width=\"14\" height=\"14\" fill=\"" << s.color << "\"/>";
    Text(out, lx + 20, ly, s.name, "start", 12);
    lx += 40 + TextWidthPx(s.name, 12);
  }
}

// One box (quartiles, median, whiskers to 1.5 IQR, outliers as dots) at x0..x0+w.
template <typename Py>
void Box(std::ostringstream& out, std::vector<double> v, double x0, double w,
         const std::string& colour, const Py& py) {
  std::sort(v.begin(), v.end());
  const double q1 = Quantile(v, 0.25), q2 = Quantile(v, 0.5), q3 = Quantile(v, 0.75);
  const double reach = 1.5 * (q3 - q1);
  double lo = q1, hi = q3;
  for (double x : v) {
    if (x >= q1 - reach) lo = std::min(lo, x);
    if (x <= q3 + reach) hi = std::max(hi, x);
  }
  const double xm = x0 + 0.5 * w;
  out << "<line x1=\"" << Num(xm) << "\" y1=\"" << Num(py(lo)) << "\" x2=\"" << Num(xm)
      << "\" y2=\"" << Num(py(hi)) << "\" stroke=\"" << colour << "\"/><rect x=\"" << Num(x0)
      << "\" y=\"" << Num(py(q3)) << "\" width=\"" << Num(w) << "\" height=\""
      << Num(py(q1) - py(q3)) << "\" fill=\"" << colour << "\" fill-opacity=\"0.35\" stroke=\""
      << colour << "\"/><line x1=\"" << Num(x0) << "\" y1=\"" << Num(py(q2)) << "\" x2=\""
      << Num(x0 + w) << "\" y2=\"" << Num(py(q2)) << "\" stroke=\"" << colour
      << "\" stroke-width=\"2.5\"/>";
  // Outliers: at most 40 per box (evenly strided over the sorted values, both ends kept),
  // enough to show the tail; a real data set has thousands of windows and the page a budget.
  std::vector<double> outliers;
  for (double x : v) {
    if (x < lo || x > hi) outliers.push_back(x);
  }
  const std::size_t stride = outliers.size() / 40 + 1;
  for (std::size_t i = 0; i < outliers.size(); i += stride) {
    // The last (the largest) always: the tail's extent is what the dots are for.
    const double x = i + stride >= outliers.size() ? outliers.back() : outliers[i];
    out << "<circle cx=\"" << Num(xm) << "\" cy=\"" << Num(py(x)) << "\" r=\"1.8\" fill=\""
        << colour << "\" fill-opacity=\"0.5\"/>";
  }
  out << "\n";
}

// A chart over categories (BarChartSvg, BoxPlotSvg), y from lo to hi with a grid line at each
// tick of `yt`: the frame, the category labels, the axis titles and the legend around what
// draw_group(out, c, group_x, group_w, py) draws for category c.
template <typename DrawGroup>
std::string CategoryChartSvg(const BarChartOptions& o, const std::vector<std::string>& categories,
                             const std::vector<BarSeries>& legend, double lo, double hi,
                             const std::vector<double>& yt, const DrawGroup& draw_group) {
  const double left = 70, right = 20, top = 34, bottom = 74;
  const double pw = o.width - left - right, ph = o.height - top - bottom;
  const double group_w = categories.empty() ? pw : pw / static_cast<double>(categories.size());
  const CategoryLabels labels = LayOutCategoryLabels(categories, group_w);
  const auto py = [&](double y) { return top + ph - (y - lo) / (hi - lo) * ph; };
  std::ostringstream out;
  Open(out, o.width, o.height + static_cast<int>(labels.extra_height), o.title);
  Text(out, o.width / 2.0, 20, o.title, "middle", 15, " font-weight=\"bold\"");
  YGrid(out, left, pw, yt, py);
  for (std::size_t c = 0; c < categories.size(); ++c) {
    draw_group(out, c, left + static_cast<double>(c) * group_w, group_w, py);
    CategoryLabel(out, labels, left + (static_cast<double>(c) + 0.5) * group_w, top + ph,
                  categories[c]);
  }
  out << "<rect x=\"" << Num(left) << "\" y=\"" << Num(top) << "\" width=\"" << Num(pw)
      << "\" height=\"" << Num(ph) << "\" fill=\"none\" stroke=\"#333\"/>\n";
  AxisLabelsAndLegend(out, left, top, pw, ph, labels.extra_height, o, legend);
  out << "</svg>\n";
  return out.str();
}

}  // namespace

std::string BarChartSvg(const BarChartOptions& o, const std::vector<std::string>& categories,
                        const std::vector<BarSeries>& series) {
  double vmax = 0.0;
  for (const BarSeries& s : series) {
    for (double v : s.values) {
      if (std::isfinite(v)) vmax = std::max(vmax, v);
    }
  }
  if (!(vmax > 0.0)) vmax = 1.0;
  const auto yt = NiceTicks(0.0, vmax * 1.05, 6);
  const double ymax = std::max(vmax * 1.05, yt.empty() ? vmax : yt.back());
  const double bars = std::max<double>(1.0, static_cast<double>(series.size()));
  const auto draw_bars = [&](std::ostringstream& out, std::size_t c, double group_x,
                             double group_w, const auto& py) {
    const double bar_w = 0.8 * group_w / bars;
    for (std::size_t s = 0; s < series.size(); ++s) {
      const double v = c < series[s].values.size() ? series[s].values[c] : 0.0;
      if (!std::isfinite(v)) continue;
      out << "<rect x=\"" << Num(group_x + 0.1 * group_w + static_cast<double>(s) * bar_w)
          << "\" y=\"" << Num(py(v)) << "\" width=\"" << Num(bar_w) << "\" height=\""
          << Num(py(0.0) - py(v)) << "\" fill=\"" << series[s].color << "\"><title>"
          << EscapeXml(categories[c]) << " " << EscapeXml(series[s].name) << ": " << v
          << "</title></rect>";
    }
  };
  return CategoryChartSvg(o, categories, series, 0.0, ymax, yt, draw_bars);
}

std::string BoxPlotSvg(const BarChartOptions& o, const std::vector<std::string>& categories,
                       const std::vector<BoxSeries>& series) {
  Range yr;
  yr.Add(0.0);
  for (const BoxSeries& s : series) {
    for (const auto& values : s.samples) {
      for (double v : values) yr.Add(v);
    }
  }
  yr.Pad(0.05);
  yr.lo = std::max(yr.lo, 0.0);  // errors: never below zero
  const double boxes = std::max<double>(1.0, static_cast<double>(series.size()));
  const auto draw_boxes = [&](std::ostringstream& out, std::size_t c, double group_x,
                              double group_w, const auto& py) {
    const double box_w = 0.7 * group_w / boxes;
    for (std::size_t k = 0; k < series.size(); ++k) {
      if (c >= series[k].samples.size() || series[k].samples[c].empty()) continue;
      const double x0 = group_x + 0.15 * group_w + static_cast<double>(k) * box_w;
      Box(out, series[k].samples[c], x0 + 0.1 * box_w, 0.8 * box_w, series[k].color, py);
    }
  };
  std::vector<BarSeries> legend;
  for (const BoxSeries& s : series) legend.push_back({s.name, s.color, {}});
  return CategoryChartSvg(o, categories, legend, yr.lo, yr.hi, NiceTicks(yr.lo, yr.hi, 6),
                          draw_boxes);
}

std::string HeatMapSvg(const std::string& title, const std::vector<std::string>& labels,
                       const std::vector<std::vector<double>>& values, double lo, double hi,
                       int cell_px) {
  const double n = static_cast<double>(labels.size());
  const double top = 40, bar_w = 18, bar_gap = 30;
  const double grid = n * cell_px;
  // Room for the longest row label on the left ("wheel_separation" was cut at 70 px); column
  // labels upright under their cells when they do not fit a cell's width (they overlapped).
  double widest = 0.0;
  for (const std::string& l : labels) widest = std::max(widest, TextWidthPx(l, 12));
  const double left = std::max(70.0, widest + 12);
  const CategoryLabels columns = LayOutCategoryLabels(labels, cell_px);
  // As wide as the title needs: a three-parameter matrix is narrower than its title.
  const int width =
      static_cast<int>(std::max(left + grid + bar_gap + bar_w + 50, TextWidthPx(title, 15) + 20));
  const int height = static_cast<int>(top + grid + 20 + columns.extra_height);
  auto colour = [&](double v) {
    // Diverging blue (lo) - white (middle) - red (hi).
    double u = (v - lo) / (hi - lo);
    u = std::clamp(std::isfinite(u) ? u : 0.5, 0.0, 1.0);
    const double a = std::abs(2.0 * u - 1.0);
    const int fade = static_cast<int>(std::lround(255.0 * (1.0 - a)));
    return u >= 0.5 ? StrFormat("#ff%02x%02x", fade, fade) : StrFormat("#%02x%02xff", fade, fade);
  };
  std::ostringstream out;
  Open(out, width, height, title);
  Text(out, width / 2.0, 20, title, "middle", 15, " font-weight=\"bold\"");
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const double c = static_cast<double>(i) * cell_px + cell_px / 2.0;
    Text(out, left - 6, top + c + 4, labels[i], "end", 12);
    CategoryLabel(out, columns, left + c, top + grid, labels[i]);
    for (std::size_t j = 0; j < labels.size(); ++j) {
      const double v = i < values.size() && j < values[i].size() ? values[i][j] : 0.0;
      const double x = left + static_cast<double>(j) * cell_px;
      const double y = top + static_cast<double>(i) * cell_px;
      out << "<rect x=\"" << Num(x) << "\" y=\"" << Num(y) << "\" width=\"" << cell_px
          << "\" height=\"" << cell_px << "\" fill=\"" << colour(v) << "\" stroke=\"#fff\"/>";
      // Two decimals, four (smaller) where two would round a correlation that is not exactly 1
      // to 1.00: a strongly correlated pair (0.9993 on a differential drive's circles) must not
      // read as the diagonal.
      const bool near_one = i != j && std::abs(v) >= 0.995 && std::abs(v) < 1.0;
      const bool dark = std::abs((v - lo) / (hi - lo) * 2.0 - 1.0) > 0.6;
      Text(out, x + cell_px / 2.0, y + cell_px / 2.0 + 4,
           StrFormat(near_one ? "%.4f" : "%.2f", v), "middle", near_one ? 10 : 11,
           dark ? " fill=\"#fff\"" : "");
    }
  }
  const double bx = left + grid + bar_gap;
  const int steps = 20;
  for (int s = 0; s < steps; ++s) {
    const double v = hi - (hi - lo) * (s + 0.5) / steps;
    out << "<rect x=\"" << Num(bx) << "\" y=\"" << Num(top + grid * s / steps) << "\" width=\""
        << Num(bar_w) << "\" height=\"" << Num(grid / steps + 0.5) << "\" fill=\"" << colour(v)
        << "\"/>";
  }
  Text(out, bx + bar_w + 4, top + 10, TickLabel(hi, 0.1), "start", 11);
  Text(out, bx + bar_w + 4, top + grid / 2 + 4, TickLabel(0.5 * (lo + hi), 0.1), "start", 11);
  Text(out, bx + bar_w + 4, top + grid, TickLabel(lo, 0.1), "start", 11);
  out << "</svg>\n";
  return out.str();
}

}  // namespace fitcal::io
