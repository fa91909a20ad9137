#include "pages/report_json.h"

#include <sstream>

#include "pages/report_text.h"

namespace fitcal::io {

namespace {

using namespace report_text;

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

// "summary": Table 6 rows with Palacin's improvement (positive = better).
void JsonSummary(std::ostringstream& j, const ReportData& d) {
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
}

// "statistics": evo-style statistics of the per-run quantities.
void JsonStatistics(std::ostringstream& j, const ReportData& d) {
  for (std::size_t i = 0; i < d.statistics.size(); ++i) {
    const ReportStatisticsRow& s = d.statistics[i];
    const double scale = s.is_angle ? kDeg : 1.0;
    j << (i ? "," : "") << "\n    " << JsonString(s.metric + (s.is_angle ? "_deg" : ""))
      << ": {\"before\": " << JsonStats(s.before, scale)
      << ", \"after\": " << JsonStats(s.after, scale) << "}";
  }
}

// "parameters": nominal, calibrated and sigma in display units (_m or _deg).
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
}

void JsonCorrelation(std::ostringstream& j, const ReportData& d) {
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
}

void JsonIdentifiability(std::ostringstream& j, const ReportData& d) {
  j << ",\n  \"identifiability\": {\"checked\": " << (d.identifiability_checked ? "true" : "false")
    << ", \"identifiable\": " << (d.identifiable ? "true" : "false")
    << ", \"condition_number\": " << JsonNumber(d.condition_number) << ", \"warnings\": [";
  for (std::size_t i = 0; i < d.identifiability_lines.size(); ++i) {
    j << (i ? ", " : "") << JsonString(d.identifiability_lines[i]);
  }
  j << "]}";
}

void JsonCrossValidation(std::ostringstream& j, const ReportData& d) {
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
}

// "runs": every validation run before and after.
void JsonRuns(std::ostringstream& j, const ReportData& d) {
  j << ",\n  \"runs\": [";
  for (std::size_t i = 0; i < d.runs.size(); ++i) {
    const ReportRun& r = d.runs[i];
    j << (i ? "," : "") << "\n    {\"run\": " << JsonString(r.id)
      << ", \"trajectory\": " << JsonString(r.trajectory) << ", \"repetition\": " << r.repetition
      << ", \"before\": " << JsonMetrics(r.before) << ", \"after\": " << JsonMetrics(r.after)
      << ", \"ate_rmse_m\": " << JsonBeforeAfter(r.before.rms_distance_m, r.after.rms_distance_m)
      << ", \"got_worse\": " << (GotWorse(r) ? "true" : "false") << "}";
  }
}

}  // namespace

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
    << ",\n  \"held_out_runs_worse\": " << WorseCount(d) << ",\n  \"ate_rmse_m\": "
    << (all ? JsonBeforeAfter(all->before.rms_distance_m, all->after.rms_distance_m) : "null")
    << ",\n  \"cf\": " << (all ? JsonBeforeAfter(all->before.cf, all->after.cf) : "null")
    << ",\n  \"drift\": " << JsonDrift(d) << ",\n  \"comparison\": " << JsonComparison(d)
    << ",\n  \"bias\": " << JsonBias(d) << ",\n  \"noise_floor\": " << JsonNoiseFloor(d)
    << ",\n  \"training_repetitions\": " << JsonString(d.training_repetitions)
    << ",\n  \"validation_repetitions\": " << JsonString(d.validation_repetitions)
    << ",\n  \"summary\": [";
  JsonSummary(j, d);
  j << "\n  ],\n  \"statistics\": {";
  JsonStatistics(j, d);
  j << "\n  },\n  \"parameters\": [";
  JsonParameters(j, d);
  j << "\n  ],\n  \"correlation\": ";
  JsonCorrelation(j, d);
  JsonIdentifiability(j, d);
  JsonCrossValidation(j, d);
  JsonRuns(j, d);
  j << "\n  ]\n}\n";
  return j.str();
}

}  // namespace fitcal::io
