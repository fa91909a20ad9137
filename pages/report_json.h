#pragma once
// The JSON renderer of the report: metrics.json (docs/metrics_json.md), every number of the page
// for machines, SI units with angles in degrees (keys ending _deg).

#include <string>

#include "pages/report_model.h"

namespace fitcal::io {

std::string MetricsJson(const ReportData& data);

// JSON scalars, shared with the page of `diagnose` (pages/diagnose_page.h).
std::string JsonStringOf(const std::string& text);
std::string JsonNumberOf(double value);  // null when not finite

// The layout version of metrics.json (docs/metrics_json.md): raised when a key changes meaning
// or disappears; keys may be added within a version.
constexpr int kMetricsJsonVersion = 2;

}  // namespace fitcal::io
