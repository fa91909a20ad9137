#include "pages/report_markdown.h"

#include <sstream>
#include <vector>

#include "pages/report_text.h"

namespace fitcal::io {

namespace {

using namespace report_text;

// A GitHub-flavoured Markdown table cell: '|' escaped (a bare one splits the cell, as the
// "|angle|" labels did), line breaks as spaces.
std::string MdCell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c == '\n' ? ' ' : c;
  }
  return out;
}

// "| a | b |" from cells (escaped).
std::string MdRow(const std::vector<std::string>& cells) {
  std::string out = "|";
  for (const std::string& c : cells) out += " " + MdCell(c) + " |";
  return out + "\n";
}

// The header row and the separator row: the first `left` columns left-aligned, the rest
// right-aligned.
std::string MdHeader(const std::vector<std::string>& names, std::size_t left) {
  std::string out = MdRow(names) + "|";
  for (std::size_t i = 0; i < names.size(); ++i) out += i < left ? "---|" : "---:|";
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
  m << "- ATE RMSE (mean over " << all.runs
    << " held-out runs, no alignment): " << Fmt("%.1f", 1e3 * all.before.rms_distance_m) << " -> "
    << Fmt("%.1f mm", 1e3 * all.after.rms_distance_m) << " ("
    << ChangePercentText(all.before.rms_distance_m, all.after.rms_distance_m) << ")\n";
  std::string worse;
  int n = 0;
  for (const ReportRun& r : d.runs) {
    if (!GotWorse(r)) continue;
    worse += (n++ ? ", " : "") + r.id;
  }
  m << "- held-out runs that got worse: " << n << " of " << d.runs.size()
    << (n > 0 ? " (" + worse + ")" : "") << "\n";
  for (const std::string& line : d.never_worse_lines) m << "- **worse:** " << line << "\n";
  m << "\n";
}

void MdSummary(std::ostringstream& m, const ReportData& d) {
  m << "## Summary (Palacin Table 6)\n\nchange = 100 (after - before) / before: negative is a "
       "smaller error, as in every table here.\n\n";
  std::vector<std::string> header = {"group", "runs", ""};
  for (const Column& c : kColumns) header.push_back(c.label);
  m << MdHeader(header, 3);
  for (const ReportSummaryRow& row : d.summary) {
    for (int part = 0; part < 3; ++part) {
      std::vector<std::string> cells = {part == 0 ? row.group : "",
                                        part == 0 ? std::to_string(row.runs) : "",
                                        part == 0   ? "before"
                                        : part == 1 ? "after"
                                                    : "change"};
      for (const Column& c : kColumns) {
        const double b = ValueOf(c, row.before), a = ValueOf(c, row.after);
        cells.push_back(part == 2 ? ChangePercentText(b, a) : Fmt(FormatOf(c), part == 0 ? b : a));
      }
      m << MdRow(cells);
    }
  }
  m << "\n## Per trajectory\n\n";
  m << MdHeader({"trajectory", "runs", "CF before", "CF after", "final position before [mm]",
                 "after [mm]"},
                1);
  for (const ReportSummaryRow& row : d.trajectories) {
    m << MdRow({row.group, std::to_string(row.runs), Fmt("%.4f", row.before.cf),
                Fmt("%.4f", row.after.cf), Fmt("%.1f", 1e3 * row.before.final_distance_m),
                Fmt("%.1f", 1e3 * row.after.final_distance_m) +
                    (row.after.final_distance_m > row.before.final_distance_m ? " (worse)" : "")});
  }
}

void MdDrift(std::ostringstream& m, const ReportData& d) {
  m << "\n## Drift per distance (relative pose error) and bias\n\n";
  m << MdHeader({"path length [m]", "windows", "translation before [%]", "after [%]",
                 "rotation before [deg/m]", "after [deg/m]"},
                0);
  for (const ReportDriftRow& r : d.drift) {
    // A drift that rose is flagged like a run that got worse: short windows show a wrong
    // calibration first (issue 42: 0.5 m, 0.71 -> 0.86 %, went unmarked).
    // The translation rows carry fit's judgement of the rise (within the runs' scatter or not).
    const auto flagged = [](double before, double after, const char* format,
                            const std::string& note = "") {
      return Fmt(format, after) +
             (after > before ? " (" + (note.empty() ? std::string("worse") : note) + ")" : "");
    };
    m << MdRow({Fmt("%g", r.length_m), std::to_string(r.windows),
                Fmt("%.2f", r.before_translation_percent),
                flagged(r.before_translation_percent, r.after_translation_percent, "%.2f",
                        r.never_worse_note),
                Fmt("%.3f", kDeg * r.before_rotation_rad_per_m),
                flagged(kDeg * r.before_rotation_rad_per_m, kDeg * r.after_rotation_rad_per_m,
                        "%.3f")});
  }
  m << "\n";
  m << MdHeader({"signed mean final error", "x [mm]", "y [mm]", "heading [deg]"}, 1);
  for (bool after : {false, true}) {
    const ReportBias& b = after ? d.bias_after : d.bias_before;
    m << MdRow({after ? "after" : "before", Fmt("%+.1f", 1e3 * b.x_m), Fmt("%+.1f", 1e3 * b.y_m),
                Fmt("%+.3f", kDeg * b.heading_rad)});
  }
}

void MdStatistics(std::ostringstream& m, const ReportData& d) {
  m << "\n## Statistics over validation runs (evo names)\n\n";
  m << MdHeader({"metric", "", "rmse", "mean", "median", "std", "min", "max"}, 2);
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
  m << MdHeader(header, 2);
  for (const ReportParameter& p : d.parameters) {
    const double s = ParamScale(p);
    const char* fmt = p.is_angle ? "%.4f" : "%.6f";
    std::vector<std::string> cells = {p.name,
                                      p.unit,
                                      Fmt(fmt, p.nominal * s),
                                      Fmt(fmt, p.calibrated * s),
                                      p.has_sigma ? Fmt("%.2g", p.sigma * s) : "-",
                                      p.held ? "-" : ParameterChangeText(p),
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
  m << MdHeader({"", "nominal", "calibrated parameters alone", "parameters + effects"}, 1)
    << MdRow({"held-out CF", Fmt("%.4f", d.summary.back().before.cf),
              Fmt("%.4f", d.cf_parameters_only), Fmt("%.4f", d.summary.back().after.cf)})
    << "\n";
  m << MdHeader({"effect", "parameter", "value", "+-1 sigma"}, 2);
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
  m << MdHeader({"calibration", "verdict", "held-out CF", "final position error [mm]",
                 "final |heading error| [deg]"},
                2);
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
    << "\n- validation: " << RunsText(d.runs.size()) << " (repetitions " << d.validation_repetitions
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
      << ". Fits: " << d.cv_objective << ".\n";
  }
  return m.str();
}

}  // namespace fitcal::io
