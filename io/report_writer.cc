#include "io/report_writer.h"

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

}  // namespace

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
    for (const ReportRun& r : data.runs) {
      gt.lines.push_back(r.ground_truth_xy);
      before.lines.push_back(r.before_xy);
      after.lines.push_back(r.after_xy);
    }
    XYPlotOptions o;
    o.id = "flower";
    o.title = "Validation runs in their start frame (the flower)";
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
    o.x_label = "trajectory (R straight, G counter-clockwise, B clockwise)";
    o.y_label = "final position error [mm]";
    f.final_distance_bars = BarChartSvg(o, order, {bd, ad});
    o.title = "Final heading error per trajectory (mean over validation repetitions)";
    o.y_label = "final |heading error| [deg]";
    f.final_angle_bars = BarChartSvg(o, order, {ba, aa});
  }
  if (data.has_correlation) {
    std::vector<std::string> labels;
    for (const ReportParameter& p : data.parameters) labels.push_back(p.name);
    f.correlation = HeatMapSvg("Correlation of the fitted parameters (-1 blue, +1 red)", labels,
                               data.correlation);
  }
  for (const ReportRun& r : data.runs) {
    SvgSeries bd = Series(kBeforeName, kBeforeColour), ad = Series(kAfterName, kAfterColour);
    SvgSeries ba = bd, aa = ad;
    bd.lines.emplace_back();
    ad.lines.emplace_back();
    ba.lines.emplace_back();
    aa.lines.emplace_back();
    for (SvgSeries* s : {&bd, &ad, &ba, &aa}) s->draw_markers = true;
    for (std::size_t i = 0; i < r.t_s.size(); ++i) {
      bd.lines[0].push_back({r.t_s[i], 1e3 * r.before_distance_m[i]});
      ad.lines[0].push_back({r.t_s[i], 1e3 * r.after_distance_m[i]});
      ba.lines[0].push_back({r.t_s[i], kDeg * r.before_angle_rad[i]});
      aa.lines[0].push_back({r.t_s[i], kDeg * r.after_angle_rad[i]});
    }
    XYPlotOptions o;
    o.width = 520;
    o.height = 360;
    o.include_origin = true;
    o.id = "run" + std::to_string(f.error_along_time.size()) + "-distance";
    o.title = r.id + ": distance error (Eq. 8)";
    o.x_label = "time since start [s]";
    o.y_label = "distance error [mm]";
    std::string both = XYPlotSvg(o, {bd, ad});
    o.id = "run" + std::to_string(f.error_along_time.size()) + "-heading";
    o.title = r.id + ": heading error (Eq. 9)";
    o.y_label = "|heading error| [deg]";
    both += XYPlotSvg(o, {ba, aa});
    f.error_along_time.push_back(both);
  }
  return f;
}

std::string ReportHtml(const ReportData& d) {
  const ReportFigures f = MakeReportFigures(d);
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    << "<title>fitcal validation report</title>\n<style>\n"
    << "body{font-family:sans-serif;margin:24px;max-width:1300px;color:#222}\n"
    << "table{border-collapse:collapse;margin:8px 0 16px}\n"
    << "th,td{border:1px solid #bbb;padding:3px 8px;text-align:right}\n"
    << "th:first-child,td:first-child{text-align:left}\n"
    << "th{background:#f0f0f0}\n"
    << ".warn{background:#fff3cd;border:1px solid #e0b000;padding:8px 12px;white-space:pre-wrap;"
       "font-family:monospace}\n"
    << ".ok{background:#e6f4ea;border:1px solid #5a5;padding:8px 12px}\n"
    << ".figs{display:flex;flex-wrap:wrap;gap:12px}\n"
    << "figure{margin:0 0 12px}figcaption{font-size:13px;color:#555;max-width:640px}\n"
    << ".better{color:#060}.worse{color:#a00}\n"
    << "</style>\n</head>\n<body>\n";
  h << "<h1>fitcal validation report</h1>\n<p>Robot <b>" << EscapeXml(d.robot_name)
    << "</b>, data set <code>" << EscapeXml(d.dataset) << "</code>, calibration <code>"
    << EscapeXml(d.calibration) << "</code>, fitcal " << EscapeXml(d.tool_version) << ".<br>"
    << "Validation: " << d.runs.size() << " runs (repetitions "
    << EscapeXml(d.validation_repetitions)
    << ") that the fit did not use; training: " << d.training_runs << " runs (repetitions "
    << EscapeXml(d.training_repetitions) << ").<br>"
    << "Odometry sub-sampled at the ground-truth times by <b>" << EscapeXml(d.sampling)
    << "</b> time" << (d.sampling == "nearest" ? " (as Palacin et al. 2022)" : " interpolation")
    << ". Before = nominal parameters, after = calibrated parameters";
  if (!d.calibrated_effects.empty()) {
    h << " with the effects";
    for (std::size_t i = 0; i < d.calibrated_effects.size(); ++i)
      h << (i ? "; " : " ") << "<code>" << EscapeXml(d.calibrated_effects[i]) << "</code>";
  }
  h << ".</p>\n";

  h << "<h2>Summary (Palacin Table 6)</h2>\n<p>Averages over the validation runs; improvement = "
       "100 (before &minus; after) / before, positive is better.</p>\n<table>\n<tr><th>group</th>"
       "<th>runs</th><th></th>";
  for (const Column& c : kColumns) h << "<th>" << EscapeXml(c.label) << "</th>";
  h << "</tr>\n";
  for (const ReportSummaryRow& row : d.summary) {
    for (int part = 0; part < 3; ++part) {
      h << "<tr>";
      if (part == 0) {
        h << "<td rowspan=\"3\"><b>" << EscapeXml(row.group) << "</b></td><td rowspan=\"3\">"
          << row.runs << "</td>";
      }
      h << "<td>" << (part == 0 ? "before" : part == 1 ? "after" : "improvement") << "</td>";
      for (const Column& c : kColumns) {
        const double b = ValueOf(c, row.before), a = ValueOf(c, row.after);
        if (part == 2) {
          const double imp = Improvement(b, a);
          h << "<td class=\"" << (imp >= 0 ? "better" : "worse") << "\">" << Fmt("%+.1f %%", imp)
            << "</td>";
        } else {
          h << "<td>" << Fmt(FormatOf(c), part == 0 ? b : a) << "</td>";
        }
      }
      h << "</tr>\n";
    }
  }
  h << "</table>\n";

  h << "<h2>Trajectories</h2>\n<div class=\"figs\">\n<figure>" << f.flower
    << "<figcaption>Each validation run drawn from its own start pose (origin, heading +x). "
       "Grey: ground truth; dashed vermillion: odometry with the nominal parameters; blue: "
       "odometry with the calibrated parameters. Compare Palacin Fig. 9-10.</figcaption>"
       "</figure>\n<figure>"
    << f.end_points
    << "<figcaption>The end of every validation run, magnified: where the odometry ended "
       "relative to the ground truth (origin). A tight blue cluster at the origin is a good "
       "calibration.</figcaption></figure>\n</div>\n";
  h << "<h2>Final error per trajectory</h2>\n<figure>" << f.final_distance_bars
    << "</figure>\n<figure>" << f.final_angle_bars << "</figure>\n";

  h << "<h2 id=\"errors\">Error along time</h2>\n<p>Run: <select id=\"runsel\" "
       "onchange=\"showRun(this.value)\">\n";
  for (std::size_t i = 0; i < d.runs.size(); ++i) {
    h << "<option value=\"run" << i << "\">" << EscapeXml(d.runs[i].id) << "</option>\n";
  }
  h << "</select> (the odometry at each ground-truth time; Eq. 8 and 9)</p>\n";
  for (std::size_t i = 0; i < d.runs.size(); ++i) {
    h << "<div class=\"run figs\" id=\"run" << i << "\""
      << (i == 0 ? "" : " style=\"display:none\"") << ">\n"
      << f.error_along_time[i] << "</div>\n";
  }
  h << "<script>\nfunction showRun(id){document.querySelectorAll('div.run').forEach("
       "function(d){d.style.display=(d.id===id)?'flex':'none';});}\n</script>\n";

  h << "<h2 id=\"statistics\">Statistics over validation runs (named as "
       "evo)</h2>\n<table>\n<tr><th>metric</th>"
       "<th></th><th>rmse</th><th>mean</th><th>median</th><th>std</th><th>min</th><th>max</th>"
       "</tr>\n";
  for (const ReportStatisticsRow& s : d.statistics) {
    const double scale = s.is_angle ? kDeg : 1.0;
    const char* fmt = s.is_angle ? "%.3f" : "%.4f";
    for (int part = 0; part < 2; ++part) {
      const ReportStatistics& v = part == 0 ? s.before : s.after;
      h << "<tr>";
      if (part == 0) {
        h << "<td rowspan=\"2\">" << EscapeXml(s.metric) << (s.is_angle ? " [deg]" : "") << "</td>";
      }
      h << "<td>" << (part == 0 ? "before" : "after") << "</td>";
      for (double x : {v.rmse, v.mean, v.median, v.std, v.min, v.max}) {
        h << "<td>" << Fmt(fmt, x * scale) << "</td>";
      }
      h << "</tr>\n";
    }
  }
  h << "</table>\n";

  h << "<h2 id=\"parameters\">Parameters</h2>\n<p>" << EscapeXml(d.uncertainty_note)
    << "</p>\n<table>\n"
    << "<tr><th>parameter</th><th>unit</th><th>nominal</th><th>calibrated</th>"
       "<th>&plusmn;1 sigma</th><th>change</th>"
    << (d.has_cv ? "<th>CV mean</th><th>CV std</th><th>CV min</th><th>CV max</th>" : "")
    << "</tr>\n";
  for (const ReportParameter& p : d.parameters) {
    const double s = ParamScale(p);
    const char* fmt = p.is_angle ? "%.4f" : "%.6f";
    h << "<tr><td>" << EscapeXml(p.name) << "</td><td>" << EscapeXml(p.unit) << "</td><td>"
      << Fmt(fmt, p.nominal * s) << "</td><td>" << Fmt(fmt, p.calibrated * s) << "</td><td>"
      << (p.has_sigma ? Fmt("%.2g", p.sigma * s) : "-") << "</td><td>"
      << Fmt("%+.2f %%", p.nominal != 0.0 ? 100.0 * (p.calibrated - p.nominal) / p.nominal : 0.0)
      << "</td>";
    if (d.has_cv) {
      h << "<td>" << Fmt(fmt, p.cv_mean * s) << "</td><td>" << Fmt("%.2g", p.cv_std * s)
        << "</td><td>" << Fmt(fmt, p.cv_min * s) << "</td><td>" << Fmt(fmt, p.cv_max * s)
        << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</table>\n";
  if (!f.correlation.empty()) h << "<figure>" << f.correlation << "</figure>\n";

  h << "<h2 id=\"identifiability\">Identifiability</h2>\n";
  if (d.identifiable) {
    h << "<p class=\"ok\">The training runs determine all nine parameters (condition number "
      << Fmt("%.3g", d.condition_number)
      << " in relative units; no parameter pair correlated beyond 0.99).</p>\n";
  } else {
    h << "<div class=\"warn\">";
    for (const std::string& line : d.identifiability_lines) h << EscapeXml(line) << "\n";
    h << "</div>\n";
  }

  if (d.has_cv) {
    h << "<h2>Leave-one-repetition-out cross-validation</h2>\n<p>Each fold fits on all "
         "repetitions but one and validates on the one left out. Validation CF (calibrated): mean "
      << Fmt("%.4f", d.cv_cf_after.mean) << ", std " << Fmt("%.4f", d.cv_cf_after.std) << ", min "
      << Fmt("%.4f", d.cv_cf_after.min) << ", max " << Fmt("%.4f", d.cv_cf_after.max)
      << " (nominal: mean " << Fmt("%.4f", d.cv_cf_before.mean)
      << "). The parameter spread across folds is in the parameter table; the folds share all but "
         "one repetition, so that spread understates the uncertainty of one fit (a jackknife "
         "estimate multiplies the CV std by sqrt(folds - 1)).</p>\n<table>\n<tr><th>held-out "
         "repetition</th><th>converged</th><th>training CF</th><th>validation CF before</th>"
         "<th>validation CF after</th></tr>\n";
    for (const ReportFold& fold : d.folds) {
      h << "<tr><td>" << fold.held_out_repetition << "</td><td>" << (fold.usable ? "yes" : "NO")
        << "</td><td>" << Fmt("%.4f", fold.cf_training) << "</td><td>"
        << Fmt("%.4f", fold.cf_validation_before) << "</td><td>"
        << Fmt("%.4f", fold.cf_validation_after) << "</td></tr>\n";
    }
    h << "</table>\n";
  }

  h << "<h2>Per-run metrics</h2>\n<details><summary>" << d.runs.size()
    << " validation runs (also in metrics.csv)</summary>\n<table>\n<tr><th>run</th>";
  for (const Column& c : kColumns) h << "<th>" << EscapeXml(c.label) << "<br>before / after</th>";
  h << "</tr>\n";
  for (const ReportRun& r : d.runs) {
    h << "<tr><td>" << EscapeXml(r.id) << "</td>";
    for (const Column& c : kColumns) {
      h << "<td>" << Fmt(FormatOf(c), ValueOf(c, r.before)) << " / "
        << Fmt(FormatOf(c), ValueOf(c, r.after)) << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</table>\n</details>\n</body>\n</html>\n";
  return h.str();
}

std::string ReportMarkdown(const ReportData& d) {
  std::ostringstream m;
  m << "# fitcal validation report\n\n"
    << "- robot: " << d.robot_name << "\n- data set: `" << d.dataset << "`\n- calibration: `"
    << d.calibration << "`\n- fitcal " << d.tool_version << "\n- validation: " << d.runs.size()
    << " runs (repetitions " << d.validation_repetitions << "), training: " << d.training_runs
    << " runs (repetitions " << d.training_repetitions << ")\n- odometry sampled at the "
    << "ground-truth times by " << d.sampling << " time\n";
  for (const std::string& e : d.calibrated_effects) m << "- calibrated effect: " << e << "\n";
  m << "\n## Summary (Palacin Table 6)\n\n"
    << "| group | runs | |";
  for (const Column& c : kColumns) m << " " << c.label << " |";
  m << "\n|---|---:|---|";
  for (std::size_t i = 0; i < std::size(kColumns); ++i) m << "---:|";
  m << "\n";
  for (const ReportSummaryRow& row : d.summary) {
    for (int part = 0; part < 3; ++part) {
      m << "| " << (part == 0 ? row.group : "") << " | "
        << (part == 0 ? std::to_string(row.runs) : "") << " | "
        << (part == 0   ? "before"
            : part == 1 ? "after"
                        : "improvement")
        << " |";
      for (const Column& c : kColumns) {
        const double b = ValueOf(c, row.before), a = ValueOf(c, row.after);
        m << " "
          << (part == 2 ? Fmt("%+.1f %%", Improvement(b, a)) : Fmt(FormatOf(c), part == 0 ? b : a))
          << " |";
      }
      m << "\n";
    }
  }
  m << "\n## Statistics over validation runs (evo names)\n\n| metric | | rmse | mean | median | "
       "std | min | max |\n|---|---|---:|---:|---:|---:|---:|---:|\n";
  for (const ReportStatisticsRow& s : d.statistics) {
    const double scale = s.is_angle ? kDeg : 1.0;
    for (int part = 0; part < 2; ++part) {
      const ReportStatistics& v = part == 0 ? s.before : s.after;
      m << "| " << (part == 0 ? s.metric + (s.is_angle ? " [deg]" : "") : "") << " | "
        << (part == 0 ? "before" : "after") << " |";
      for (double x : {v.rmse, v.mean, v.median, v.std, v.min, v.max}) {
        m << " " << Fmt(s.is_angle ? "%.3f" : "%.4f", x * scale) << " |";
      }
      m << "\n";
    }
  }
  m << "\n## Parameters\n\n"
    << d.uncertainty_note << "\n\n| parameter | unit | nominal | calibrated | +-1 sigma |"
    << (d.has_cv ? " CV std | CV min | CV max |" : "") << "\n|---|---|---:|---:|---:|"
    << (d.has_cv ? "---:|---:|---:|" : "") << "\n";
  for (const ReportParameter& p : d.parameters) {
    const double s = ParamScale(p);
    const char* fmt = p.is_angle ? "%.4f" : "%.6f";
    m << "| " << p.name << " | " << p.unit << " | " << Fmt(fmt, p.nominal * s) << " | "
      << Fmt(fmt, p.calibrated * s) << " | " << (p.has_sigma ? Fmt("%.2g", p.sigma * s) : "-")
      << " |";
    if (d.has_cv) {
      m << " " << Fmt("%.2g", p.cv_std * s) << " | " << Fmt(fmt, p.cv_min * s) << " | "
        << Fmt(fmt, p.cv_max * s) << " |";
    }
    m << "\n";
  }
  m << "\n## Identifiability\n\n";
  if (d.identifiable) {
    m << "All nine parameters are determined by the training runs (condition number "
      << Fmt("%.3g", d.condition_number) << ").\n";
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
  c << "\n";
  for (const ReportRun& r : d.runs) {
    c << r.id << "," << r.trajectory << "," << r.repetition;
    for (const ReportMetrics* m : {&r.before, &r.after}) {
      for (const Column& col : kColumns) c << "," << JsonNumber(ValueOf(col, *m));
    }
    c << "\n";
  }
  return c.str();
}

std::string MetricsJson(const ReportData& d) {
  std::ostringstream j;
  j << "{\n  \"tool_version\": " << JsonString(d.tool_version)
    << ",\n  \"dataset\": " << JsonString(d.dataset)
    << ",\n  \"calibration\": " << JsonString(d.calibration)
    << ",\n  \"robot\": " << JsonString(d.robot_name)
    << ",\n  \"odometry_sampling\": " << JsonString(d.sampling) << ",\n  \"calibrated_effects\": [";
  for (std::size_t i = 0; i < d.calibrated_effects.size(); ++i)
    j << (i ? ", " : "") << JsonString(d.calibrated_effects[i]);
  j << "]"
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
      << "\": " << (p.has_sigma ? JsonNumber(p.sigma * s) : "null");
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
  j << ",\n  \"identifiability\": {\"identifiable\": " << (d.identifiable ? "true" : "false")
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
      << "}";
  }
  j << "\n  ]\n}\n";
  return j.str();
}

}  // namespace fitcal::io
