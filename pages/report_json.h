#pragma once
// The JSON renderer of the report: metrics.json (docs/metrics_json.md), every number of the page
// for machines, SI units with angles in degrees (keys ending _deg).

#include <string>

#include "pages/report_model.h"

namespace fitcal::io {

std::string MetricsJson(const ReportData& data);

// JSON text, shared with the page of `diagnose` (pages/diagnose_page.h) and metrics.csv's numbers:
// a quoted, escaped string; a number as %.10g, or null when not finite; {"before": b, "after": a}.
std::string JsonString(const std::string& s);
std::string JsonNumber(double v);
inline std::string JsonBool(bool b) { return b ? "true" : "false"; }
std::string JsonBeforeAfter(double before, double after);

// A parameter's `"unit": ..., "value": ..., "sigma": ...` in SI (m or rad; null sigma when none):
// the generic keys carry no unit in their names, so they carry no degrees.
std::string JsonSiValue(const ReportParameter& p);

// The layout version of metrics.json (docs/metrics_json.md): raised when a key changes meaning
// or disappears; keys may be added within a version.
// Version 3: a parameter's generic `value` and `sigma` are SI (m, rad) as its `unit` says; degrees
// stay under the keys that end in _deg.
constexpr int kMetricsJsonVersion = 3;

}  // namespace fitcal::io
