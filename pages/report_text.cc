#include "pages/report_text.h"

#include <algorithm>

#include "odometry/text_format.h"

namespace fitcal::io::report_text {

const char* const kGroundTruthColour = "#9a9a9a";
const char* const kBeforeColour = "#d55e00";
const char* const kAfterColour = "#0072b2";
const char* const kBeforeName = "odometry, nominal parameters";
const char* const kAfterName = "odometry, calibrated parameters";

std::string Fmt(const char* format, double v) { return FormatDouble(format, v); }

double Improvement(double before, double after) {
  return before > 0.0 ? 100.0 * (before - after) / before : 0.0;
}

std::string ChangePercentText(double before, double after) {
  return before > 0.0 ? Fmt("%+.1f %%", -Improvement(before, after)) : "-";
}

std::string RunsText(std::size_t n) { return std::to_string(n) + (n == 1 ? " run" : " runs"); }

const Column kColumns[7] = {
    {"rms_distance_m", "RMS distance error [m] (Eq. 12)", false, &ReportMetrics::rms_distance_m},
    {"rms_angle", "RMS |angle| error [deg] (Eq. 13)", true, &ReportMetrics::rms_angle_rad},
    {"max_distance_m", "max distance error [m] (Eq. 10)", false, &ReportMetrics::max_distance_m},
    {"max_angle", "max |angle| error [deg] (Eq. 11)", true, &ReportMetrics::max_angle_rad},
    {"final_distance_m", "final position error [m]", false, &ReportMetrics::final_distance_m},
    {"final_angle", "final |angle| error [deg]", true, &ReportMetrics::final_angle_rad},
    {"cf", "CF (Eq. 14, m and rad)", false, &ReportMetrics::cf},
};

std::string KeyOf(const Column& c) { return std::string(c.key) + (c.is_angle ? "_deg" : ""); }
double ValueOf(const Column& c, const ReportMetrics& m) {
  return m.*c.field * (c.is_angle ? kDeg : 1.0);
}
const char* FormatOf(const Column& c) { return c.is_angle ? "%.3f" : "%.4f"; }

double ParamScale(const ReportParameter& p) { return p.is_angle ? kDeg : 1.0; }

ChangeTerms ChangeTermsOf(bool is_angle, bool is_position, double nominal) {
  if (is_angle) return ChangeTerms::kDegrees;
  return is_position || nominal == 0.0 ? ChangeTerms::kMetres : ChangeTerms::kPercent;
}

std::string ParameterChangeText(const ReportParameter& p) {
  const double change = p.calibrated - p.nominal;
  switch (ChangeTermsOf(p.is_angle, p.is_position, p.nominal)) {
    case ChangeTerms::kDegrees:
      return Fmt("%+.3f deg", change * kDeg);
    case ChangeTerms::kMetres:
      return Fmt("%+.4g m", change);
    case ChangeTerms::kPercent:
      break;
  }
  return Fmt("%+.2f %%", 100.0 * change / p.nominal);
}

std::vector<std::size_t> WorstRuns(const ReportData& data, std::size_t most) {
  std::vector<std::size_t> order(data.runs.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return data.runs[a].after.cf > data.runs[b].after.cf;
  });
  order.resize(std::min(order.size(), most));
  return order;
}

double ColouredTrackScale(const ReportRun& r) {
  const double hi = std::max(r.before.max_distance_m, r.after.max_distance_m);
  double samples = 0.0;
  for (const auto* e : {&r.before_distance_m, &r.after_distance_m}) {
    for (double v : *e) samples = std::max(samples, v);
  }
  const double out = std::max(hi, samples);
  return out > 0.0 ? out : 1.0;
}

}  // namespace fitcal::io::report_text
