#include "io/svg_plot.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace fitcal::io {

namespace {

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

std::string TickLabel(double v, double step) {
  char buf[32];
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  std::snprintf(buf, sizeof buf, "%.*f", std::min(decimals, 6), std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
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

}  // namespace

std::string EscapeXml(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
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

std::string XYPlotSvg(const XYPlotOptions& o, const std::vector<SvgSeries>& series) {
  Range xr, yr;
  for (const SvgSeries& s : series) {
    for (const auto& line : s.lines) {
      for (const Point2& p : line) {
        xr.Add(p.x);
        yr.Add(p.y);
      }
    }
  }
  if (o.include_origin) {
    xr.Add(0.0);
    yr.Add(0.0);
  }
  xr.Pad(0.05);
  yr.Pad(0.05);
  if (o.x_lo < o.x_hi) xr = Range{o.x_lo, o.x_hi};
  if (o.y_lo < o.y_hi) yr = Range{o.y_lo, o.y_hi};
  const double left = 70, right = 20, top = 34, bottom = 50;
  const double pw = o.width - left - right;
  // Legend below the plot: as many entries per row as their longest name allows.
  std::size_t longest = 1;
  for (const SvgSeries& s : series) longest = std::max(longest, s.name.size());
  const std::size_t per_row = std::max<std::size_t>(
      1, static_cast<std::size_t>(pw / (40.0 + 6.5 * static_cast<double>(longest))));
  const double legend_h = 22.0 * static_cast<double>((series.size() + per_row - 1) / per_row);
  const double ph = o.height - top - bottom - legend_h;
  if (o.equal_aspect) {
    // Widen the smaller span so one unit has the same length on both axes.
    const double scale = std::max((xr.hi - xr.lo) / pw, (yr.hi - yr.lo) / ph);
    const double xc = 0.5 * (xr.lo + xr.hi), yc = 0.5 * (yr.lo + yr.hi);
    xr = Range{xc - 0.5 * scale * pw, xc + 0.5 * scale * pw};
    yr = Range{yc - 0.5 * scale * ph, yc + 0.5 * scale * ph};
  }
  auto px = [&](double x) { return left + (x - xr.lo) / (xr.hi - xr.lo) * pw; };
  auto py = [&](double y) { return top + ph - (y - yr.lo) / (yr.hi - yr.lo) * ph; };

  std::ostringstream out;
  Open(out, o.width, o.height, o.title);
  Text(out, o.width / 2.0, 20, o.title, "middle", 15, " font-weight=\"bold\"");
  out << "<rect x=\"" << Num(left) << "\" y=\"" << Num(top) << "\" width=\"" << Num(pw)
      << "\" height=\"" << Num(ph) << "\" fill=\"none\" stroke=\"#333\"/>\n";
  const auto xt = NiceTicks(xr.lo, xr.hi, std::max(3, static_cast<int>(pw / 80)));
  const auto yt = NiceTicks(yr.lo, yr.hi, std::max(3, static_cast<int>(ph / 50)));
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1.0;
  const double ystep = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  for (double t : xt) {
    out << "<line x1=\"" << Num(px(t)) << "\" y1=\"" << Num(top) << "\" x2=\"" << Num(px(t))
        << "\" y2=\"" << Num(top + ph) << "\" stroke=\"#e4e4e4\"/>\n";
    Text(out, px(t), top + ph + 16, TickLabel(t, xstep), "middle", 11);
  }
  for (double t : yt) {
    out << "<line x1=\"" << Num(left) << "\" y1=\"" << Num(py(t)) << "\" x2=\"" << Num(left + pw)
        << "\" y2=\"" << Num(py(t)) << "\" stroke=\"#e4e4e4\"/>\n";
    Text(out, left - 6, py(t) + 4, TickLabel(t, ystep), "end", 11);
  }
  Text(out, left + pw / 2, top + ph + 36, o.x_label, "middle", 13);
  const double ylx = 18, yly = top + ph / 2;
  Text(out, ylx, yly, o.y_label, "middle", 13,
       (" transform=\"rotate(-90 " + Num(ylx) + " " + Num(yly) + ")\"").c_str());
  // Ids must be unique in a document that embeds several plots.
  static std::atomic<int> next_clip_id{0};
  const std::string clip_id =
      "clip-" + (o.id.empty() ? std::to_string(next_clip_id++) : EscapeXml(o.id));
  out << "<clipPath id=\"" << clip_id << "\"><rect x=\"" << Num(left) << "\" y=\"" << Num(top)
      << "\" width=\"" << Num(pw) << "\" height=\"" << Num(ph) << "\"/></clipPath>\n";
  out << "<g clip-path=\"url(#" << clip_id << ")\">\n";
  for (const SvgSeries& s : series) {
    out << "<g opacity=\"" << s.opacity << "\">";
    for (const auto& line : s.lines) {
      if (s.draw_lines && line.size() > 1) {
        out << "<polyline fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\""
            << s.line_width << "\"";
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
  out << "</g>\n";
  const double ly0 = top + ph + 56;
  for (std::size_t i = 0; i < series.size(); ++i) {
    const double lx = left + static_cast<double>(i % per_row) * (pw / static_cast<double>(per_row));
    const double ly = ly0 + 22.0 * static_cast<double>(i / per_row);
    const SvgSeries& s = series[i];
    if (s.draw_lines) {
      out << "<line x1=\"" << Num(lx) << "\" y1=\"" << Num(ly - 4) << "\" x2=\"" << Num(lx + 24)
          << "\" y2=\"" << Num(ly - 4) << "\" stroke=\"" << s.color << "\" stroke-width=\"2.5\"";
      if (!s.dash.empty()) out << " stroke-dasharray=\"" << s.dash << "\"";
      out << "/>";
    }
    if (s.draw_markers) {
      out << "<circle cx=\"" << Num(lx + 12) << "\" cy=\"" << Num(ly - 4) << "\" r=\"4\" fill=\""
          << s.color << "\"/>";
    }
    Text(out, lx + 30, ly, s.name, "start", 12);
  }
  out << "</svg>\n";
  return out.str();
}

std::string BarChartSvg(const BarChartOptions& o, const std::vector<std::string>& categories,
                        const std::vector<BarSeries>& series) {
  double vmax = 0.0;
  for (const BarSeries& s : series) {
    for (double v : s.values) {
      if (std::isfinite(v)) vmax = std::max(vmax, v);
    }
  }
  if (!(vmax > 0.0)) vmax = 1.0;
  const double left = 70, right = 20, top = 34, bottom = 74;
  const double pw = o.width - left - right;
  const double ph = o.height - top - bottom;
  const auto yt = NiceTicks(0.0, vmax * 1.05, 6);
  const double ymax = std::max(vmax * 1.05, yt.empty() ? vmax : yt.back());
  const double ystep = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  auto py = [&](double y) { return top + ph - y / ymax * ph; };
  std::ostringstream out;
  Open(out, o.width, o.height, o.title);
  Text(out, o.width / 2.0, 20, o.title, "middle", 15, " font-weight=\"bold\"");
  for (double t : yt) {
    out << "<line x1=\"" << Num(left) << "\" y1=\"" << Num(py(t)) << "\" x2=\"" << Num(left + pw)
        << "\" y2=\"" << Num(py(t)) << "\" stroke=\"#e4e4e4\"/>\n";
    Text(out, left - 6, py(t) + 4, TickLabel(t, ystep), "end", 11);
  }
  const double group_w = categories.empty() ? pw : pw / static_cast<double>(categories.size());
  const double bar_w = 0.8 * group_w / std::max<double>(1.0, static_cast<double>(series.size()));
  for (std::size_t c = 0; c < categories.size(); ++c) {
    const double gx = left + static_cast<double>(c) * group_w + 0.1 * group_w;
    for (std::size_t s = 0; s < series.size(); ++s) {
      const double v = c < series[s].values.size() ? series[s].values[c] : 0.0;
      if (!std::isfinite(v)) continue;
      out << "<rect x=\"" << Num(gx + static_cast<double>(s) * bar_w) << "\" y=\"" << Num(py(v))
          << "\" width=\"" << Num(bar_w) << "\" height=\"" << Num(py(0.0) - py(v)) << "\" fill=\""
          << series[s].color << "\"><title>" << EscapeXml(categories[c]) << " "
          << EscapeXml(series[s].name) << ": " << v << "</title></rect>";
    }
    const double cx = left + (static_cast<double>(c) + 0.5) * group_w;
    Text(out, cx, top + ph + 14, categories[c], "middle", 10);
  }
  out << "<rect x=\"" << Num(left) << "\" y=\"" << Num(top) << "\" width=\"" << Num(pw)
      << "\" height=\"" << Num(ph) << "\" fill=\"none\" stroke=\"#333\"/>\n";
  Text(out, left + pw / 2, top + ph + 34, o.x_label, "middle", 13);
  const double ylx = 18, yly = top + ph / 2;
  Text(out, ylx, yly, o.y_label, "middle", 13,
       (" transform=\"rotate(-90 " + Num(ylx) + " " + Num(yly) + ")\"").c_str());
  for (std::size_t s = 0; s < series.size(); ++s) {
    const double lx = left + static_cast<double>(s) * 220.0;
    const double ly = top + ph + 58;
    out << "<rect x=\"" << Num(lx) << "\" y=\"" << Num(ly - 11)
        << "\" width=\"14\" height=\"14\" fill=\"" << series[s].color << "\"/>";
    Text(out, lx + 20, ly, series[s].name, "start", 12);
  }
  out << "</svg>\n";
  return out.str();
}

std::string HeatMapSvg(const std::string& title, const std::vector<std::string>& labels,
                       const std::vector<std::vector<double>>& values, double lo, double hi,
                       int cell_px) {
  const double n = static_cast<double>(labels.size());
  const double left = 70, top = 40, bar_w = 18, bar_gap = 30;
  const double grid = n * cell_px;
  const int width = static_cast<int>(left + grid + bar_gap + bar_w + 50);
  const int height = static_cast<int>(top + grid + 20);
  auto colour = [&](double v) {
    // Diverging blue (lo) - white (middle) - red (hi).
    double u = (v - lo) / (hi - lo);
    u = std::clamp(std::isfinite(u) ? u : 0.5, 0.0, 1.0);
    const double a = std::abs(2.0 * u - 1.0);
    const int fade = static_cast<int>(std::lround(255.0 * (1.0 - a)));
    const int full = 255;
    const int r = u >= 0.5 ? full : fade, b = u >= 0.5 ? fade : full;
    const int g = fade;
    char buf[16];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", r, g, b);
    return std::string(buf);
  };
  std::ostringstream out;
  Open(out, width, height, title);
  Text(out, width / 2.0, 20, title, "middle", 15, " font-weight=\"bold\"");
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const double c = static_cast<double>(i) * cell_px + cell_px / 2.0;
    Text(out, left - 6, top + c + 4, labels[i], "end", 12);
    Text(out, left + c, top + grid + 15, labels[i], "middle", 12);
    for (std::size_t j = 0; j < labels.size(); ++j) {
      const double v = i < values.size() && j < values[i].size() ? values[i][j] : 0.0;
      const double x = left + static_cast<double>(j) * cell_px;
      const double y = top + static_cast<double>(i) * cell_px;
      out << "<rect x=\"" << Num(x) << "\" y=\"" << Num(y) << "\" width=\"" << cell_px
          << "\" height=\"" << cell_px << "\" fill=\"" << colour(v) << "\" stroke=\"#fff\"/>";
      char buf[16];
      std::snprintf(buf, sizeof buf, "%.2f", v);
      const bool dark = std::abs((v - lo) / (hi - lo) * 2.0 - 1.0) > 0.6;
      Text(out, x + cell_px / 2.0, y + cell_px / 2.0 + 4, buf, "middle", 11,
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
