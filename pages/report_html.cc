#include "pages/report_html.h"

#include <algorithm>

#include "pages/report_figures.h"
#include "pages/report_text.h"
#include "pages/svg_plot.h"

namespace fitcal::io {

namespace {

using namespace report_text;

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
    // A path is one long word (a data set in a temporary directory, "trained on data set
    // /tmp/..."), in code or in prose: it breaks rather than push a phone's page sideways.
    "code,p,li{overflow-wrap:anywhere}\n"
    // A run id is one long word (rosbag imports name runs by topic and time): it breaks rather
    // than push a phone's page wider than the screen.
    "h1,h2,h3{overflow-wrap:anywhere}\n"
    ".warn{background:#fff3cd;border:1px solid #e0b000;padding:8px 12px;white-space:pre-wrap;"
    "font-family:monospace;overflow-x:auto}\n"
    ".ok{background:#e6f4ea;border:1px solid #5a5;padding:8px 12px}\n"
    ".banner{padding:10px 16px;border:2px solid;margin:12px 0 20px}\n"
    ".banner h2{margin:0 0 6px}\n"
    ".PASS{background:#e6f4ea;border-color:#2a7a2a}\n"
    ".WARN{background:#fff3cd;border-color:#b08000}\n"
    ".FAIL{background:#fde2e1;border-color:#b00020}\n"
    ".banner li.PASS,.banner li.WARN,.banner li.FAIL{background:none;border:none}\n"
    ".banner li.SKIP{color:#555}\n"
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
    ".figs.flagged{border-left:4px solid #b00020;padding-left:6px}\n"
    // A table whose columns carry a verdict (the runs that got worse, diagnose's tests and
    // effects) becomes one card per row on a phone, each cell under its column's name: no column
    // hides beyond the right edge (the "after" that explains the flag, the decision).
    "@media (max-width:700px){table.stack,table.stack tbody,table.stack tr,table.stack td"
    "{display:block}table.stack tr:first-child{display:none}table.stack tr{border:1px solid #bbb;"
    "margin:0 0 8px;padding:2px 0}table.stack td{border:none;text-align:left;white-space:normal;"
    "min-width:0;overflow-wrap:anywhere}table.stack td::before{content:attr(data-label) \": \";"
    "font-weight:bold;color:#333}}\n";

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
  const int worse = WorseRunCount(d);
  h << "<ul class=\"key\" id=\"key\">\n<li>ATE RMSE (mean over " << all.runs
    << " held-out runs, no alignment): <b>" << Fmt("%.1f", 1e3 * all.before.rms_distance_m)
    << " &rarr; " << Fmt("%.1f mm", 1e3 * all.after.rms_distance_m) << "</b> ("
    << ChangePercentText(all.before.rms_distance_m, all.after.rms_distance_m) << ")</li>\n";
  for (const ReportDriftRow& r : d.drift) {
    // Coloured and said like the runs that got worse (issue 42: a worse 0.5 m drift went unmarked).
    const bool translation_worse = r.after_translation_percent > r.before_translation_percent;
    const bool drift_worse =
        translation_worse || r.after_rotation_rad_per_m > r.before_rotation_rad_per_m;
    // fit's judgement of a translation rise: within the runs' scatter or beyond it.
    const std::string said =
        translation_worse && !r.never_worse_note.empty() ? r.never_worse_note : "worse";
    h << "<li" << (drift_worse ? " class=\"worse\"" : "") << ">drift over "
      << Fmt("%g m", r.length_m) << ": <b>" << Fmt("%.2f", r.before_translation_percent)
      << " &rarr; " << Fmt("%.2f %%", r.after_translation_percent) << "</b>, "
      << Fmt("%.3f", kDeg * r.before_rotation_rad_per_m) << " &rarr; "
      << Fmt("%.3f deg/m", kDeg * r.after_rotation_rad_per_m)
      << (drift_worse ? " (" + EscapeXml(said) + ")" : "") << "</li>\n";
  }
  for (const std::string& line : d.never_worse_lines) {
    h << "<li class=\"worse\">" << EscapeXml(line) << "</li>\n";
  }
  h << "<li" << (worse > 0 ? " class=\"worse\"" : "") << ">held-out runs that got worse: " << worse
    << " of " << d.runs.size() << (worse > 0 ? " (<a href=\"#worse\">list</a>)" : "")
    << "</li>\n</ul>\n";
}

void HtmlHeader(std::ostringstream& h, const ReportData& d) {
  h << "<p>Robot <b>" << EscapeXml(d.robot_name) << "</b>, data set <code>" << EscapeXml(d.dataset)
    << "</code>, calibration <code>" << EscapeXml(d.calibration) << "</code>, fitcal "
    << EscapeXml(d.tool_version) << ".<br>"
    << "Validation: " << RunsText(d.runs.size()) << " (repetitions "
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
    h << "<td class=\"k\">" << (part == 0 ? "before" : part == 1 ? "after" : "change") << "</td>";
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
    const ReportBias& b = after ? d.bias_after : d.bias_before;
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
  for (const std::string* svgs :
       {&f.position_error_along_distance, &f.heading_error_along_distance}) {
    if (!svgs->empty()) h << "<div class=\"figs\">\n" << *svgs << "</div>\n";
  }
  if (f.drift_translation_boxes.empty()) return;
  h << "<p>Drift of every window of each length along the ground truth (the table above is "
       "their mean): box from the first to the third quartile, the median across it, whiskers "
       "to 1.5 interquartile ranges, dots beyond. The number of windows is in brackets.</p>\n"
    << "<div class=\"figs\">\n"
    << f.drift_translation_boxes << f.drift_rotation_boxes << "</div>\n";
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
  OpenTable(h, "", /*stacked=*/true);
  h << "<tr><th>run</th><th>CF before</th><th>CF after</th><th>ATE RMSE before [mm]</th>"
       "<th>ATE RMSE after [mm]</th></tr>\n";
  for (const ReportRun* r : worse) {
    // The "after" cells carry the flag (class v: page_render_test keeps them on the screen).
    const auto cell = [&](const char* name, double before, double after, const char* format,
                          double scale) {
      h << "<td data-label=\"" << name << " before\">" << Fmt(format, scale * before)
        << "</td><td data-label=\"" << name << " after\" class=\"v"
        << (after > before ? " worse" : "") << "\">" << Fmt(format, scale * after) << "</td>";
    };
    h << "<tr><td data-label=\"run\">" << EscapeXml(r->id) << "</td>";
    cell("CF", r->before.cf, r->after.cf, "%.4f", 1.0);
    cell("ATE RMSE [mm]", r->before.rms_distance_m, r->after.rms_distance_m, "%.1f", 1e3);
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
      << (p.held ? "-" : ParameterChangeText(p)) << "</td><td"
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
       "repetitions but one and validates on the one left out; "
    << EscapeXml(d.cv_objective) << ". Validation CF (calibrated): mean "
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

void OpenTable(std::ostringstream& h, const std::string& id, bool stacked) {
  h << "<div class=\"scroll\"" << (id.empty() ? "" : " id=\"" + id + "\"") << ">\n<table"
    << (stacked ? " class=\"stack\"" : "") << ">\n";
}
void CloseTable(std::ostringstream& h) { h << "</table>\n</div>\n"; }

std::string PageHead(const std::string& title, const std::string& heading) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
         EscapeXml(title) + "</title>\n<style>\n" + kStyle + "</style>\n</head>\n<body>\n<h1>" +
         EscapeXml(heading) + "</h1>\n";
}

std::string ReportHtml(const ReportData& d) {
  const ReportFigures f = MakeReportFigures(d);
  std::ostringstream h;
  h << PageHead("fitcal validation report: " + d.verdict, "fitcal validation report");
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

}  // namespace fitcal::io
