#include "pages/diagnose_page.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "io/text_file.h"
#include "pages/final_error_plot.h"
#include "pages/report_html.h"
#include "pages/report_json.h"
#include "pages/report_text.h"
#include "pages/svg_plot.h"

namespace fitcal::io {

namespace {

using report_text::ChangePercentText;
using report_text::kAfterColour;  // the calibration's colour, as on the report's page
using report_text::kDeg;
using report_text::Fmt;

// The residual: each held-out run's final position error in its start frame, before and after.
std::string FinalErrorsSvg(const DiagnosePageData& d) {
  FinalErrorScatter s;
  s.before_name = "nominal parameters";
  s.after_name = "written calibration";
  s.origin_name = "ground truth end point";
  s.run_opacity = 0.75;
  s.origin_opacity = 0.75;
  for (const DiagnoseHeldOutRun& r : d.held_out) {
    s.before_m.push_back(r.final_error_before_m);
    s.after_m.push_back(r.final_error_after_m);
  }
  s.plot.id = "diag-final";
  s.plot.title = "Held-out final position errors";
  s.plot.x_label = "along start-frame x [mm]";
  s.plot.y_label = "along start-frame y [mm]";
  s.plot.width = 480;
  s.plot.height = 480;
  return FinalErrorScatterSvg(s);
}

// The evidence of each fitted candidate: -log10 p against the Bonferroni threshold.
std::string EvidenceSvg(const DiagnosePageData& d) {
  std::vector<std::string> names;
  BarSeries p{"-log10 p (paired t test on held-out runs)", kAfterColour, {}};
  BarSeries t{"-log10 threshold (alpha / candidates fitted)", "#999999", {}};
  for (const DiagnoseCandidate& c : d.candidates) {
    if (!c.fitted) continue;
    names.push_back("r" + std::to_string(c.round) + " " + c.effect);
    p.values.push_back(-std::log10(std::max(c.p_value, 1e-300)));
    t.values.push_back(c.threshold > 0.0 ? -std::log10(c.threshold) : 0.0);
  }
  if (names.empty()) return "";
  BarChartOptions o;
  o.title = "Evidence of each effect fitted";
  o.x_label = "round and effect";
  o.y_label = "-log10 p";
  o.width = 720;
  return BarChartSvg(o, names, {p, t});
}

// Before and after per held-out run: CF with the nominal against CF with the calibration.
std::string HeldOutSvg(const DiagnosePageData& d) {
  SvgSeries runs, diagonal;
  runs.name = "held-out run";
  runs.color = kAfterColour;
  runs.draw_lines = false;
  runs.draw_markers = true;
  runs.opacity = 0.75;
  runs.lines.emplace_back();
  double hi = 0.0;
  for (const DiagnoseHeldOutRun& r : d.held_out) {
    runs.lines[0].push_back({r.cf_before, r.cf_after});
    hi = std::max({hi, r.cf_before, r.cf_after});
  }
  diagonal.name = "no change (above: worse)";
  diagonal.color = "#999999";
  diagonal.dash = "5 3";
  diagonal.lines = {{Point2{0.0, 0.0}, Point2{hi, hi}}};
  XYPlotOptions o;
  o.id = "diag-cf";
  o.title = "CF of each held-out run";
  o.x_label = "CF, nominal parameters";
  o.y_label = "CF, written calibration";
  o.width = 480;
  o.height = 480;
  o.include_origin = true;
  return XYPlotSvg(o, {diagonal, runs});
}

void HtmlStructure(std::ostringstream& h, const DiagnosePageData& d) {
  h << "<h2 id=\"structure\">Residual structure tested</h2>\n";
  OpenTable(h, "", /*stacked=*/true);
  h << "<tr><th>test</th><th>statistic</th><th>p</th><th>result</th><th>what it says</th></tr>\n";
  for (const DiagnoseStructureTest& t : d.structure) {
    h << "<tr><td data-label=\"test\">" << EscapeXml(t.name)
      << "</td><td data-label=\"statistic\" class=\"k\">" << EscapeXml(t.detail)
      << "</td><td data-label=\"p\">" << Fmt("%.2g", t.p_value)
      << "</td><td data-label=\"result\" class=\"v"
      << (t.significant ? " worse\">structure" : "\">none found")
      << "</td><td data-label=\"what it says\" class=\"k\">"
      << EscapeXml(t.significant ? t.meaning : "") << "</td></tr>\n";
  }
  CloseTable(h);
  h << "<figure>" << FinalErrorsSvg(d)
    << "<figcaption>Where each held-out run ended relative to its ground truth (origin), with the "
       "nominal parameters and with the written calibration: a cluster off the origin is "
       "structure the model lacks.</figcaption></figure>\n";
}

void HtmlCandidates(std::ostringstream& h, const DiagnosePageData& d) {
  h << "<h2 id=\"effects\">Each effect tried</h2>\n";
  if (d.candidates.empty()) {
    h << "<p>No candidate effect was tried.</p>\n";
    return;
  }
  OpenTable(h, "", /*stacked=*/true);
  h << "<tr><th>round</th><th>effect</th><th>separable</th><th>fitted</th><th>mean "
       "improvement</th><th>p</th><th>threshold</th><th>&Delta;BIC</th><th>explains</th>"
       "<th>decision</th></tr>\n";
  for (const DiagnoseCandidate& c : d.candidates) {
    h << "<tr><td data-label=\"round\">" << c.round << "</td><td data-label=\"effect\" "
      << "class=\"k\">" << EscapeXml(c.effect) << "</td><td data-label=\"separable\">"
      << Fmt("%.3f", c.separable_fraction) << (c.resolvable ? "" : " (not resolvable)")
      << "</td><td data-label=\"fitted\">" << (c.fitted ? "yes" : "no")
      << "</td><td data-label=\"mean improvement\">"
      << (c.fitted ? Fmt("%.3g", c.mean_improvement) : "-") << "</td><td data-label=\"p\">"
      << (c.fitted ? Fmt("%.2g", c.p_value) : "-") << "</td><td data-label=\"threshold\">"
      << Fmt("%.2g", c.threshold) << "</td><td data-label=\"&Delta;BIC\">"
      << (c.fitted ? Fmt("%+.1f", c.delta_bic) : "-") << "</td><td data-label=\"explains\">"
      << (c.explains ? "yes" : "no") << "</td><td data-label=\"decision\" class=\"k v"
      << (c.accepted ? " better" : "") << "\">" << (c.accepted ? "<b>accepted</b> " : "")
      << EscapeXml(c.decision) << "</td></tr>\n";
  }
  CloseTable(h);
  const std::string evidence = EvidenceSvg(d);
  if (!evidence.empty()) {
    h << "<figure class=\"wide\">" << evidence
      << "<figcaption>An effect is accepted only when its bar clears the threshold and it also "
         "lowers BIC and explains the lack of fit (table).</figcaption></figure>\n";
  }
}

void HtmlHeldOut(std::ostringstream& h, const DiagnosePageData& d) {
  const double cf_b = HeldOutMean(d.held_out, &DiagnoseHeldOutRun::cf_before);
  const double cf_a = HeldOutMean(d.held_out, &DiagnoseHeldOutRun::cf_after);
  const double ate_b = HeldOutMean(d.held_out, &DiagnoseHeldOutRun::ate_before_m);
  const double ate_a = HeldOutMean(d.held_out, &DiagnoseHeldOutRun::ate_after_m);
  int worse = 0;
  // As the report's GotWorse: the CF or the ATE rose.
  for (const DiagnoseHeldOutRun& r : d.held_out) {
    worse += r.cf_after > r.cf_before || r.ate_after_m > r.ate_before_m ? 1 : 0;
  }
  h << "<h2 id=\"heldout\">Before and after on the held-out runs</h2>\n<ul class=\"key\">"
    << "<li>CF (Eq. 14, mean over " << d.held_out.size() << " runs): <b>" << Fmt("%.4f", cf_b)
    << " &rarr; " << Fmt("%.4f", cf_a) << "</b> (" << ChangePercentText(cf_b, cf_a) << ")</li>"
    << "<li>ATE RMSE (no alignment): <b>" << Fmt("%.1f", 1e3 * ate_b) << " &rarr; "
    << Fmt("%.1f mm", 1e3 * ate_a) << "</b> (" << ChangePercentText(ate_b, ate_a) << ")</li><li"
    << (worse > 0 ? " class=\"worse\"" : "")
    << ">held-out runs that got worse (CF or ATE rose): " << worse << " of " << d.held_out.size()
    << "</li></ul>\n<p>These are computed as <code>fitcal "
       "report</code> computes them (the odometry replayed from the window's start and sampled "
       "at the ground-truth times, Palacin Eq. 8-14), so <code>report</code> on "
       "<code>calibrated.yaml</code> and the same runs prints the same CF. The result gate below "
       "chose among the fits by the CF of the effect fit's own track replay (each run replayed "
       "through the ground-truth anchors its objective uses), which differs from the report's "
       "by the replay, not by the runs.</p>\n";
  OpenTable(h);
  h << "<tr><th>result gate candidate</th><th>held-out CF (track replay)</th></tr>\n";
  for (const DiagnoseGateRow& g : d.gate) {
    h << "<tr><td>" << EscapeXml(g.name) << (g.selected ? " <b>(written)</b>" : "") << "</td><td>"
      << Fmt("%.5f", g.cf_held_out) << "</td></tr>\n";
  }
  CloseTable(h);
  h << "<figure>" << HeldOutSvg(d)
    << "<figcaption>Each held-out run's CF with the nominal parameters (x) and with the written "
       "calibration (y): below the dashed line it improved.</figcaption></figure>\n";
}

void HtmlCalibration(std::ostringstream& h, const DiagnosePageData& d) {
  h << "<h2 id=\"parameters\">Written calibration</h2>\n";
  OpenTable(h);
  h << "<tr><th>parameter</th><th>unit</th><th>nominal</th><th>value</th><th>&plusmn;1 "
       "sigma</th><th>status</th></tr>\n";
  for (const ReportParameter& p : d.parameters) {
    const double s = p.is_angle ? kDeg : 1.0;
    const char* fmt = p.is_angle ? "%.4f" : "%.6f";
    h << "<tr><td>" << EscapeXml(p.name) << "</td><td>" << EscapeXml(p.unit) << "</td><td>"
      << Fmt(fmt, p.nominal * s) << "</td><td>" << Fmt(fmt, p.calibrated * s) << "</td><td>"
      << (p.has_sigma ? Fmt("%.2g", p.sigma * s) : "-") << "</td><td"
      << (p.held ? " class=\"held\">held at nominal" : ">fitted") << "</td></tr>\n";
  }
  CloseTable(h);
  for (const ReportEffect& e : d.effects) {
    h << "<p>Effect <b>" << EscapeXml(e.name) << "</b>:";
    for (std::size_t k = 0; k < e.values.size(); ++k) {
      h << " " << EscapeXml(e.parameter_names[k]) << " = " << Fmt("%.6g", e.values[k])
        << " &plusmn; " << Fmt("%.2g", e.sigmas[k]);
    }
    h << "</p>\n";
  }
}

}  // namespace

double HeldOutMean(const std::vector<DiagnoseHeldOutRun>& runs, double DiagnoseHeldOutRun::*field) {
  double sum = 0.0;
  for (const DiagnoseHeldOutRun& r : runs) sum += r.*field;
  return runs.empty() ? 0.0 : sum / static_cast<double>(runs.size());
}

std::string DiagnoseHtml(const DiagnosePageData& d) {
  std::ostringstream h;
  h << PageHead("fitcal diagnose: " + d.level, "fitcal diagnose") << "<div class=\"banner "
    << (d.level == "EFFECTS_NAMED" ? "PASS" : "WARN")
    << "\" id=\"verdict\">\n<h2>" << EscapeXml(d.level) << "</h2>\n<p>" << EscapeXml(d.conclusion)
    << "</p>\n</div>\n<p>Robot <b>" << EscapeXml(d.robot_name) << "</b> (" << EscapeXml(d.model)
    << "), data set <code>" << EscapeXml(d.dataset) << "</code>, " << EscapeXml(d.split)
    << ", fitcal " << EscapeXml(d.tool_version) << ".</p>\n";
  HtmlStructure(h, d);
  HtmlCandidates(h, d);
  HtmlHeldOut(h, d);
  h << "<h2 id=\"unexplained\">What stays unexplained</h2>\n";
  if (d.unexplained.empty()) {
    h << "<p class=\"ok\">Nothing: no test above finds structure left in the residual.</p>\n";
  } else {
    h << "<ul>\n";
    for (const std::string& line : d.unexplained) h << "<li>" << EscapeXml(line) << "</li>\n";
    h << "</ul>\n";
  }
  HtmlCalibration(h, d);
  h << "<h2>The diagnosis as printed</h2>\n<details><summary>text report"
    << (d.csv_written ? " (residuals in residuals.csv)" : " (residual CSVs: rerun with --csv)")
    << "</summary>\n<pre class=\"warn\">" << EscapeXml(d.text_report) << "</pre>\n</details>\n"
    << "</body>\n</html>\n";
  return h.str();
}

std::string DiagnoseMetricsJson(const DiagnosePageData& d) {
  std::ostringstream j;
  j << "{\n  \"version\": " << kMetricsJsonVersion << ",\n  \"kind\": \"diagnose\""
    << ",\n  \"tool_version\": " << JsonString(d.tool_version)
    << ",\n  \"dataset\": " << JsonString(d.dataset)
    << ",\n  \"split\": " << JsonString(d.split)
    << ",\n  \"robot\": " << JsonString(d.robot_name)
    << ",\n  \"verdict\": {\"level\": " << JsonString(d.level)
    << ", \"message\": " << JsonString(d.conclusion) << "}"
    << ",\n  \"selected\": " << JsonString(d.selected)
    << ",\n  \"held_out_runs\": " << d.held_out.size() << ",\n  \"cf\": "
    << JsonBeforeAfter(HeldOutMean(d.held_out, &DiagnoseHeldOutRun::cf_before),
                       HeldOutMean(d.held_out, &DiagnoseHeldOutRun::cf_after))
    << ",\n  \"ate_rmse_m\": "
    << JsonBeforeAfter(HeldOutMean(d.held_out, &DiagnoseHeldOutRun::ate_before_m),
                       HeldOutMean(d.held_out, &DiagnoseHeldOutRun::ate_after_m))
    << ",\n  \"gate_cf\": [" << Joined(d.gate, ", ", [](const DiagnoseGateRow& g) {
         return "{\"name\": " + JsonString(g.name) + ", \"cf\": " + JsonNumber(g.cf_held_out) +
                ", \"selected\": " + JsonBool(g.selected) + "}";
       })
    << "],\n  \"parameters\": [" << Joined(d.parameters, ",", [](const ReportParameter& p) {
         return "\n    {\"name\": " + JsonString(p.name) + ", " + JsonSiValue(p) +
                ", \"held\": " + JsonBool(p.held) + "}";
       })
    << "\n  ],\n  \"effects\": [" << Joined(d.effects, ", ", [](const ReportEffect& e) {
         return "{\"name\": " + JsonString(e.name) + ", \"values\": [" +
                Joined(e.values, ", ", JsonNumber) + "]}";
       })
    << "],\n  \"candidates\": [" << Joined(d.candidates, ",", [](const DiagnoseCandidate& c) {
         return "\n    {\"round\": " + std::to_string(c.round) +
                ", \"effect\": " + JsonString(c.effect) + ", \"fitted\": " + JsonBool(c.fitted) +
                ", \"p_value\": " + (c.fitted ? JsonNumber(c.p_value) : "null") +
                ", \"accepted\": " + JsonBool(c.accepted) + "}";
       })
    << "\n  ],\n  \"runs\": [" << Joined(d.held_out, ",", [](const DiagnoseHeldOutRun& r) {
         return "\n    {\"run\": " + JsonString(r.id) +
                ", \"cf\": " + JsonBeforeAfter(r.cf_before, r.cf_after) +
                ", \"ate_rmse_m\": " + JsonBeforeAfter(r.ate_before_m, r.ate_after_m) + "}";
       })
    << "\n  ]\n}\n";
  return j.str();
}

}  // namespace fitcal::io
