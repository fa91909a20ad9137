#pragma once
// The HTML renderer of the report: index.html, one self-contained file with inline SVG figures
// (io/report_figures.h), no network; every number is the model's (io/report_model.h).

#include <string>

#include "io/report_model.h"

namespace fitcal::io {

std::string ReportHtml(const ReportData& data);

// Shared by the pages of `report` and `diagnose` (io/diagnose_page.h): one style sheet (readable
// from a 390 px phone to a 1400 px desktop).
std::string PageStyleSheet();

}  // namespace fitcal::io
