#include "pages/report_json.h"

#include <sstream>

#include "io/text_file.h"
#include "odometry/text_format.h"
#include "pages/report_text.h"

namespace fitcal::io {

namespace {

using namespace report_text;

// {"key": value, ...} of the Table 6 columns, `value_of` giving each column's number.
template <typename ValueOf>
std::string JsonColumns(const ValueOf& value_of) {
  return "{" + Joined(kColumns, ", ", [&](const Column& c) {
           return JsonString(KeyOf(c)) + ": " + JsonNumber(value_of(c));
         }) + "}";
}

std::string JsonMetrics(const ReportMetrics& m) {
  return JsonColumns([&](const Column& c) { return ValueOf(c, m); });
}

std::string JsonStats(const ReportStatistics& s, double scale) {
  return "{\"rmse\": " + JsonNumber(s.rmse * scale) + ", \"mean\": " + JsonNumber(s.mean * scale) +
         ", \"median\": " + JsonNumber(s.median * scale) +
         ", \"std\": " + JsonNumber(s.std * scale) + ", \"min\": " + JsonNumber(s.min * scale) +
         ", \"max\": " + JsonNumber(s.max * scale) + "}";
}

// {"level": "WARN", "reasons": [{"level", "check", "section", "message"}, ...]}
std::string JsonVerdict(const ReportData& d) {
  return "{\"level\": " + JsonString(d.verdict) + ", \"reasons\": [" +
         Joined(d.verdict_reasons, ",", [](const ReportVerdictReason& r) {
           return "\n    {\"level\": " + JsonString(r.level) + ", \"check\": " +
                  JsonString(r.check) + ", \"section\": " + JsonString(r.section) +
                  ", \"message\": " + JsonString(r.message) + "}";
         }) + "]}";
}

// {"cf_parameters_only": x, "list": [{"name", "parameters": [{"name", "value", "sigma"}]}]}
std::string JsonEffects(const ReportData& d) {
  const auto effect = [](const ReportEffect& e) {
    std::string out = "{\"name\": " + JsonString(e.name) + ", \"parameters\": [";
    for (std::size_t k = 0; k < e.values.size(); ++k) {
      out += std::string(k ? ", " : "") + "{\"name\": " + JsonString(e.parameter_names[k]) +
             ", \"value\": " + JsonNumber(e.values[k]) + ", \"sigma\": " + JsonNumber(e.sigmas[k]) +
             "}";
    }
    return out + "]}";
  };
  return "{\"cf_parameters_only\": " +
         (d.effects.empty() ? std::string("null") : JsonNumber(d.cf_parameters_only)) +
         ", \"list\": [" + Joined(d.effects, ", ", effect) + "]}";
}

std::string JsonTrajectories(const ReportData& d) {
  return "[" + Joined(d.trajectories, ",", [](const ReportSummaryRow& row) {
           return "\n    {\"trajectory\": " + JsonString(row.group) +
                  ", \"runs\": " + std::to_string(row.runs) +
                  ", \"before\": " + JsonMetrics(row.before) +
                  ", \"after\": " + JsonMetrics(row.after) + "}";
         }) + "]";
}

std::string JsonDrift(const ReportData& d) {
  return "[" + Joined(d.drift, ", ", [](const ReportDriftRow& r) {
           return "{\"length_m\": " + JsonNumber(r.length_m) +
                  ", \"windows\": " + std::to_string(r.windows) + ", \"translation_percent\": " +
                  JsonBeforeAfter(r.before_translation_percent, r.after_translation_percent) +
                  ", \"rotation_deg_per_m\": " +
                  JsonBeforeAfter(kDeg * r.before_rotation_rad_per_m,
                                  kDeg * r.after_rotation_rad_per_m) +
                  ", \"windows_worse\": " + std::to_string(r.windows_worse) + "}";
         }) + "]";
}

std::string JsonBias(const ReportData& d) {
  std::string out = "{";
  for (bool after : {false, true}) {
    const ReportBias& b = after ? d.bias_after : d.bias_before;
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
  return "[" + Joined(d.comparison, ",", [](const ReportComparisonRow& c) {
           return "\n    {\"calibration\": " + JsonString(c.calibration) +
                  ", \"verdict\": " + JsonString(c.verdict) +
                  ", \"training_source\": " + JsonString(c.training_source) +
                  ", \"before\": " + JsonMetrics(c.all.before) +
                  ", \"after\": " + JsonMetrics(c.all.after) + ", \"per_trajectory_cf_after\": [" +
                  Joined(c.trajectory_cf_after, ", ", JsonNumber) + "]}";
         }) + "]";
}

// "summary": Table 6 rows with Palacin's improvement (positive = better).
std::string JsonSummary(const ReportData& d) {
  return Joined(d.summary, ",", [](const ReportSummaryRow& row) {
    return "\n    {\"group\": " + JsonString(row.group) + ", \"runs\": " +
           std::to_string(row.runs) + ",\n     \"before\": " + JsonMetrics(row.before) +
           ",\n     \"after\": " + JsonMetrics(row.after) + ",\n     \"improvement_percent\": " +
           JsonColumns([&](const Column& c) {
             return Improvement(ValueOf(c, row.before), ValueOf(c, row.after));
           }) +
           "}";
  });
}

// "statistics": evo-style statistics of the per-run quantities.
std::string JsonStatistics(const ReportData& d) {
  return Joined(d.statistics, ",", [](const ReportStatisticsRow& s) {
    const double scale = s.is_angle ? kDeg : 1.0;
    return "\n    " + JsonString(s.metric + (s.is_angle ? "_deg" : "")) +
           ": {\"before\": " + JsonStats(s.before, scale) +
           ", \"after\": " + JsonStats(s.after, scale) + "}";
  });
}

// "parameters": nominal, calibrated and sigma in display units (_m or _deg), and in SI.
void JsonParameters(std::ostringstream& j, const ReportData& d) {
  for (std::size_t i = 0; i < d.parameters.size(); ++i) {
    const ReportParameter& p = d.parameters[i];
    const double s = ParamScale(p);
    const std::string u = p.is_angle ? "_deg" : "_m";
    j << (i ? "," : "") << "\n    {\"name\": " << JsonString(p.name) << ", \"nominal" << u
      << "\": " << JsonNumber(p.nominal * s) << ", \"calibrated" << u
      << "\": " << JsonNumber(p.calibrated * s) << ", \"sigma" << u
      << "\": " << (p.has_sigma ? JsonNumber(p.sigma * s) : "null")
      << ", \"at_bound\": " << (p.at_bound ? "true" : "false")
      << ", " << JsonSiValue(p) << ", \"held\": " << (p.held ? "true" : "false");
    if (p.has_cv) {
      j << ", \"cv_std" << u << "\": " << JsonNumber(p.cv_std * s) << ", \"cv_min" << u
        << "\": " << JsonNumber(p.cv_min * s) << ", \"cv_max" << u
        << "\": " << JsonNumber(p.cv_max * s);
    }
    j << "}";
  }
}

std::string JsonCorrelation(const ReportData& d) {
  if (!d.has_correlation) return "null";
  return "[" + Joined(d.correlation, ", ", [](const std::vector<double>& row) {
           return "[" + Joined(row, ", ", JsonNumber) + "]";
         }) + "]";
}

void JsonIdentifiability(std::ostringstream& j, const ReportData& d) {
  j << ",\n  \"identifiability\": {\"checked\": " << (d.identifiability_checked ? "true" : "false")
    << ", \"identifiable\": " << (d.identifiable ? "true" : "false")
    << ", \"condition_number\": " << JsonNumber(d.condition_number)
    << ", \"warnings\": [" << Joined(d.identifiability_lines, ", ", JsonString) << "]}";
}

void JsonCrossValidation(std::ostringstream& j, const ReportData& d) {
  if (d.has_cv) {
    j << ",\n  \"cross_validation\": {\"objective\": " << JsonString(d.cv_objective)
      << ", \"cf_validation_after\": " << JsonStats(d.cv_cf_after, 1.0)
      << ", \"cf_validation_before\": " << JsonStats(d.cv_cf_before, 1.0) << ", \"folds\": ["
      << Joined(d.folds, ", ", [](const ReportFold& f) {
           return "{\"held_out_repetition\": " + std::to_string(f.held_out_repetition) +
                  ", \"usable\": " + JsonBool(f.usable) +
                  ", \"cf_training\": " + JsonNumber(f.cf_training) +
                  ", \"cf_validation_before\": " + JsonNumber(f.cf_validation_before) +
                  ", \"cf_validation_after\": " + JsonNumber(f.cf_validation_after) + "}";
         })
      << "]}";
  }
}

// "runs": every validation run before and after.
std::string JsonRuns(const ReportData& d) {
  return Joined(d.runs, ",", [](const ReportRun& r) {
    return "\n    {\"run\": " + JsonString(r.id) + ", \"trajectory\": " + JsonString(r.trajectory) +
           ", \"repetition\": " + std::to_string(r.repetition) +
           ", \"before\": " + JsonMetrics(r.before) + ", \"after\": " + JsonMetrics(r.after) +
           ", \"ate_rmse_m\": " +
           JsonBeforeAfter(r.before.rms_distance_m, r.after.rms_distance_m) +
           ", \"got_worse\": " + JsonBool(GotWorse(r)) + "}";
  });
}

}  // namespace

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
          out += StrFormat("\\u%04x", c);
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string JsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  return StrFormat("%.10g", v);
}

std::string JsonSiValue(const ReportParameter& p) {
  return "\"unit\": " + JsonString(p.is_angle ? "rad" : p.unit) +
         ", \"value\": " + JsonNumber(p.calibrated) +
         ", \"sigma\": " + (p.has_sigma ? JsonNumber(p.sigma) : "null");
}

std::string JsonBeforeAfter(double before, double after) {
  return "{\"before\": " + JsonNumber(before) + ", \"after\": " + JsonNumber(after) + "}";
}

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
    << ",\n  \"held_out_runs_worse\": " << WorseRunCount(d) << ",\n  \"ate_rmse_m\": "
    << (all ? JsonBeforeAfter(all->before.rms_distance_m, all->after.rms_distance_m) : "null")
    << ",\n  \"cf\": " << (all ? JsonBeforeAfter(all->before.cf, all->after.cf) : "null")
    << ",\n  \"drift\": " << JsonDrift(d) << ",\n  \"comparison\": " << JsonComparison(d)
    << ",\n  \"bias\": " << JsonBias(d) << ",\n  \"noise_floor\": " << JsonNoiseFloor(d)
    << ",\n  \"training_repetitions\": " << JsonString(d.training_repetitions)
    << ",\n  \"validation_repetitions\": " << JsonString(d.validation_repetitions)
    << ",\n  \"summary\": [" << JsonSummary(d) << "\n  ],\n  \"statistics\": {"
    << JsonStatistics(d) << "\n  },\n  \"parameters\": [";
  JsonParameters(j, d);
  j << "\n  ],\n  \"correlation\": " << JsonCorrelation(d);
  JsonIdentifiability(j, d);
  JsonCrossValidation(j, d);
  j << ",\n  \"runs\": [" << JsonRuns(d) << "\n  ]\n}\n";
  return j.str();
}

}  // namespace fitcal::io
