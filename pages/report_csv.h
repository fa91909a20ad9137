#pragma once
// The CSV renderer of the report: metrics.csv, one row per validation run (Table 6 metrics before
// and after, signed final errors in the start frame).

#include <string>

#include "pages/report_model.h"

namespace fitcal::io {

std::string MetricsCsv(const ReportData& data);

}  // namespace fitcal::io
